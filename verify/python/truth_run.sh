#!/usr/bin/env bash
# One arm end to end against a known true robot (issue #39, item 5):
#   verify/python/truth_run.sh ARM [SEED] [RANDOM_DESIGNS]
# ARM: ur3 ur5 ur10 xarm7 kinova z1 panda so100 baxter (+ "-pose" for a full
# pose, e.g. ur5-pose). SEED (default 1) seeds the truth, the noise and the
# pool. RANDOM_DESIGNS (default 0) random 30-pose designs of the same pool
# are measured and calibrated too; their median true error is printed
# against the chosen design's.
# Environment: AC (the activecal binary, default target/debug/activecal),
# OUT (work directory, default /tmp/truth/ARM-SEED), NOISE (metres per axis,
# default 5e-5), ONOISE (rad per axis, full pose; default 0.01° where
# select takes --orientation-noise (passed to it), else 5e-5 = NOISE over
# the fixed orientation_scale 1 m/rad that select's prediction assumes),
# N (poses, default 30), POOL_COUNT (random pool size, default 4096),
# DRAWS (noise draws at the chosen design, default 10), SENSOR (frames or
# marker: how activecal is given the nominal marker).
# Prints one line per step and a summary: unknowns, predicted RMS (select
# --report), true RMS at 1,000 random configurations, noise-free true RMS,
# chosen / median random.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
ARM="${1:?usage: truth_run.sh ARM [SEED] [RANDOM_DESIGNS]}"
SEED="${2:-1}"
NRAND="${3:-0}"
AC="${AC:-$ROOT/target/debug/activecal}"
PY="$ROOT/.venv/bin/python"
T="$ROOT/verify/python/truth.py"
FX="$ROOT/fixtures/example-robot-data"
NOISE="${NOISE:-5e-5}"
N="${N:-30}"
POOL_COUNT="${POOL_COUNT:-4096}"
export OPENBLAS_NUM_THREADS=1

POSE=""
case "$ARM" in *-pose) POSE="--pose"; BASE_ARM="${ARM%-pose}" ;; *) BASE_ARM="$ARM" ;; esac
case "$BASE_ARM" in
  ur3) URDF=ur3_robot.urdf; TIP=tool0 ;;
  ur5) URDF=ur5_robot.urdf; TIP=tool0 ;;
  ur10) URDF=ur10_robot.urdf; TIP=tool0 ;;
  xarm7) URDF=xarm7.urdf; TIP=link_eef ;;
  kinova) URDF=kinova.urdf; TIP=j2s6s200_end_effector ;;
  z1) URDF=z1.urdf; TIP=gripperStator ;;
  panda) URDF=panda.urdf; TIP=panda_hand_tcp ;;
  so100) URDF=so100.urdf; TIP=gripper ;;
  baxter) URDF=baxter.urdf; TIP=left_gripper ;;
  *) echo "unknown arm $ARM" >&2; exit 2 ;;
esac
OUT="${OUT:-/tmp/truth/$ARM-$SEED}"
rm -rf "$OUT"; mkdir -p "$OUT"; cd "$OUT"
ROBOT="$FX/$URDF"
[ -n "$POSE" ] && ROBOT="$ROBOT:pose"

# How activecal is told the sensor (tip link + nominal marker or tool): a
# frames file, or with SENSOR=marker `--tip T --marker T@x,y,z` (a point
# sensor; a full pose keeps the frames file). One place to change.
sensor() {
  if [ "${SENSOR:-frames}" = marker ] && [ -z "$POSE" ]; then
    echo --tip "$TIP" --marker "$TIP@$(jq -r '.nominal_tool.xyz | map(tostring) | join(",")' "$OUT/truth.json")"
  else
    echo --frames "$OUT/nominal.yaml"
  fi
}

"$PY" "$T" make --urdf "$FX/$URDF" --tip "$TIP" --seed "$SEED" --out truth.json $POSE >/dev/null
"$PY" "$T" sensor-frames --truth truth.json --out nominal.yaml >/dev/null
SEL_NOISE=(--noise "$NOISE")
# A full pose: the design weighed for the orientation noise, where select
# takes --orientation-noise (it weighs with --noise, given with --report).
if [ -n "$POSE" ] && "$AC" select --help | grep -q -- --orientation-noise; then
  ONOISE="${ONOISE:-1.7453292519943296e-4}"
  SEL_NOISE+=(--orientation-noise "$ONOISE")
fi
ONOISE="${ONOISE:-5e-5}"
MEAS_NOISE=(--noise "$NOISE")
[ -n "$POSE" ] && MEAS_NOISE+=(--orientation-noise "$ONOISE")

t0=$(date +%s.%N)
"$AC" pool --robot "$ROBOT" $(sensor) --pool random --count "$POOL_COUNT" --pool-seed "$SEED" --out pool.csv --force >pool.txt
"$AC" select --robot "$ROBOT" $(sensor) --pool file:pool.csv --n "$N" --seed "$SEED" \
  "${SEL_NOISE[@]}" --report report --force --json --out design.csv >select.json
t1=$(date +%s.%N)
P=$(jq '.how_many_poses.p' report/report.json)
PRED=$(jq --argjson n "$N" '.how_many_poses.points[] | select(.n == $n) | .predicted.position_rms_mm' report/report.json)
SAME=$(jq --argjson n "$N" -c '[(.how_many_poses.points[] | select(.n == $n) | .poses | sort), (.selection.poses | sort)] | .[0] == .[1]' report/report.json)

calib() { # calib MEAS PREFIX
  "$AC" calibrate --robot "$ROBOT" $(sensor) --measurements "$1" --out "$2.urdf" --out "$2.yaml" --force --json >"$2.json" 2>"$2.err" || { echo "calibrate failed: $(tail -3 "$2.err")" >&2; return 1; }
}
DRAWS="${DRAWS:-10}"
DD=(); DM=(); DU=(); DY=()
for k in $(seq 0 $((DRAWS - 1))); do DD+=(design.csv); DM+=("meas$k.csv"); DU+=("cal$k.urdf"); DY+=("cal$k.yaml"); done
"$PY" "$T" measure --truth truth.json --design "${DD[@]}" "${MEAS_NOISE[@]}" --seed "$SEED" --out "${DM[@]}" >/dev/null
for k in $(seq 0 $((DRAWS - 1))); do calib "meas$k.csv" "cal$k"; done
t2=$(date +%s.%N)
"$PY" "$T" compare --truth truth.json --urdf "${DU[@]}" --frames "${DY[@]}" --design design.csv --seed "$SEED" >draws_compare.json
jq 'if type == "array" then .[0] else . end' draws_compare.json >compare.json
OVER=$(jq 'if type == "array" then . else [.] end | [.[].random.rms_mm] | (map(. * .) | add / length | sqrt)' draws_compare.json)
"$PY" "$T" measure --truth truth.json --design design.csv --noise 0 --seed "$SEED" --out exact.csv >/dev/null
calib exact.csv exact
"$PY" "$T" compare --truth truth.json --urdf exact.urdf --frames exact.yaml --seed "$SEED" >exact_compare.json
"$PY" "$T" compare --truth truth.json --nominal --seed "$SEED" >nominal_compare.json
t3=$(date +%s.%N)
TRUE=$(jq '.random.rms_mm' compare.json)
EXACT=$(jq '.random.rms_mm' exact_compare.json)
NOM=$(jq '.random.rms_mm' nominal_compare.json)
echo "arm=$ARM seed=$SEED unknowns=$P (Pinocchio rank $("$PY" "$T" rank --truth truth.json --n 60 | jq .rank)) poses=$N noise=${NOISE}m sensor=$(sensor | sed "s|$OUT/||")"
echo "  nominal model (true tracker, nominal marker): ${NOM} mm RMS"
echo "  select --report predicts ${PRED} mm RMS (report's N=$N design is the chosen one: $SAME)"
echo "  calibrated, true error at 1000 random configurations: ${TRUE} mm RMS (at the design's poses $(jq '.design.rms_mm' compare.json) mm)"
echo "  ratio true/predicted: $(echo "$TRUE $PRED" | awk '{printf "%.3f", $1/$2}') (one draw); over $DRAWS noise draws true RMS $OVER mm, ratio $(echo "$OVER $PRED" | awk '{printf "%.3f", $1/$2}')"
echo "  noise-free data: true error ${EXACT} mm RMS"
if [ -n "$POSE" ]; then
  echo "  orientation: true $(jq '.random.orientation_rms_deg' compare.json) deg RMS, predicted $(jq --argjson n "$N" '.how_many_poses.points[] | select(.n == $n) | .predicted.orientation_rms_deg' report/report.json) deg"
fi
echo "  times: pool+select+report $(echo "$t1 $t0" | awk '{printf "%.1f", $1-$2}') s, measure+calibrate $(echo "$t2 $t1" | awk '{printf "%.1f", $1-$2}') s, compare+exact $(echo "$t3 $t2" | awk '{printf "%.1f", $1-$2}') s"
if [ "$NRAND" -gt 0 ]; then
  D=(); M=(); U=(); Y=(); R=()
  for k in $(seq 1 "$NRAND"); do D+=("rand$k.csv"); M+=("rmeas$k.csv"); done
  "$PY" "$T" random-design --pool pool.csv --n "$N" --seed $((1000 + SEED)) --out "${D[@]}" >/dev/null
  "$PY" "$T" measure --truth truth.json --design "${D[@]}" "${MEAS_NOISE[@]}" --seed "$SEED" --out "${M[@]}" >/dev/null
  for k in $(seq 1 "$NRAND"); do
    if calib "rmeas$k.csv" "rcal$k"; then U+=("rcal$k.urdf"); Y+=("rcal$k.yaml"); else R+=("inf"); fi
  done
  t4=$(date +%s.%N)
  if [ "${#U[@]}" -gt 0 ]; then
    "$PY" "$T" compare --truth truth.json --urdf "${U[@]}" --frames "${Y[@]}" --seed "$SEED" >random_compare.json
    if [ "${#U[@]}" -eq 1 ]; then R+=("$(jq '.random.rms_mm' random_compare.json)"); else mapfile -t -O "${#R[@]}" R < <(jq '.[].random.rms_mm' random_compare.json); fi
  fi
  MED=$(printf '%s\n' "${R[@]}" | sort -g | awk '{a[NR]=$1} END {if (NR%2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}')
  echo "  $NRAND random designs: true RMS $(printf '%.4f ' "${R[@]}")mm; median $MED; chosen (over draws)/median $(echo "$OVER $MED" | awk '{printf "%.3f", $1/$2}') ($(echo "$t4 $t3" | awk '{printf "%.1f", $1-$2}') s)"
fi
