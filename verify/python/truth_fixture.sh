#!/usr/bin/env bash
# Fixtures of the truth gate that plain `cargo test` checks without Python
# (issue #39, item 5: "store what plain cargo test can check as fixtures"):
#   verify/python/truth_fixture.sh ARM [SEED]
# ARM as truth_run.sh names it (ur5, xarm7, ...; point sensor, marker given
# by a frames file). Writes fixtures/truth/ARM/:
#   nominal.yaml      the sensor as activecal is told it (tip, nominal marker)
#   design.csv        the 30 poses `activecal select` chose for it
#   meas0..9.csv      Pinocchio's true robot measured there by a tracker
#                     2.6 m away, 0.05 mm noise per axis, 10 draws
#   exact.csv         the same, noise-free
#   truth_random.csv  the true marker in the tracker's frame at 300 random
#                     configurations (noise-free): what a calibrated model
#                     must predict
#   expected.json     select's predicted RMS true error for the design and
#                     noise, and the rank of Pinocchio's identification
#                     Jacobian of a complete model (the unknowns there are)
# Needs the project venv (Pinocchio) and target/debug/activecal.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
ARM="${1:?usage: truth_fixture.sh ARM [SEED]}"
SEED="${2:-1}"
AC="${AC:-$ROOT/target/debug/activecal}"
PY="$ROOT/.venv/bin/python"
T="$ROOT/verify/python/truth.py"
FX="$ROOT/fixtures/example-robot-data"
NOISE=5e-5
export OPENBLAS_NUM_THREADS=1
case "$ARM" in
  ur3) URDF=ur3_robot.urdf; TIP=tool0 ;;
  ur5) URDF=ur5_robot.urdf; TIP=tool0 ;;
  ur10) URDF=ur10_robot.urdf; TIP=tool0 ;;
  xarm7) URDF=xarm7.urdf; TIP=link_eef ;;
  kinova) URDF=kinova.urdf; TIP=j2s6s200_end_effector ;;
  panda) URDF=panda.urdf; TIP=panda_hand_tcp ;;
  *) echo "unknown arm $ARM" >&2; exit 2 ;;
esac
DEST="$ROOT/fixtures/truth/$ARM"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
ROBOT="$FX/$URDF"
"$PY" "$T" make --urdf "$ROBOT" --tip "$TIP" --seed "$SEED" --out truth.json >/dev/null
"$PY" "$T" sensor-frames --truth truth.json --out nominal.yaml >/dev/null
"$AC" pool --robot "$ROBOT" --frames nominal.yaml --pool random --count 4096 --pool-seed "$SEED" --out pool.csv --force >/dev/null
"$AC" select --robot "$ROBOT" --frames nominal.yaml --pool file:pool.csv --n 30 --seed "$SEED" \
  --noise "$NOISE" --json --out design.csv >select.json
D=(); M=()
for k in $(seq 0 9); do D+=(design.csv); M+=("meas$k.csv"); done
"$PY" "$T" measure --truth truth.json --design "${D[@]}" --noise "$NOISE" --seed "$SEED" --out "${M[@]}" >/dev/null
"$PY" "$T" measure --truth truth.json --design design.csv --noise 0 --seed "$SEED" --out exact.csv >/dev/null
"$AC" pool --robot "$ROBOT" --frames nominal.yaml --pool random --count 300 --pool-seed $((SEED + 1000)) --margin 0 --out random.csv --force >/dev/null
"$PY" "$T" measure --truth truth.json --design random.csv --noise 0 --seed "$SEED" --out truth_random.csv >/dev/null
RANK=$("$PY" "$T" rank --truth truth.json --n 60 | jq .rank)
jq --argjson rank "$RANK" --arg arm "$ARM" --arg urdf "$URDF" --arg tip "$TIP" --argjson seed "$SEED" --argjson noise "$NOISE" \
  '{arm: $arm, urdf: $urdf, tip: $tip, seed: $seed, noise_m: $noise, pinocchio_rank: $rank,
    predicted_position_rms_mm: .predicted.position_rms_mm, predicted_configurations: .predicted.configurations}' \
  select.json >expected.json
rm -rf "$DEST"; mkdir -p "$DEST"
cp nominal.yaml design.csv meas*.csv exact.csv truth_random.csv expected.json "$DEST/"
echo "truth_fixture: $ARM -> $DEST ($(cat expected.json | jq -c .))"
