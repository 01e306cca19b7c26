#!/usr/bin/env bash
# A 2 GB ROS 2 bag is streamed, not loaded (issue #52's acceptance: peak
# memory under 500 MB). Writes the bag of a simulated calibration run with
# rosbags (verify/python/bag_truth.py: the true UR5 of verify/python/truth.py
# through a 30-pose design, /joint_states at 1 kHz, a tracker at 100 Hz on
# /tracker, and GB of raw 640x480 images on /camera/image_raw), in MCAP and
# in SQLite 3, then runs `activecal extract` on each under /usr/bin/time -v
# and prints its peak resident memory (MB) and wall time (s). Exits 1 when a
# peak is 500 MB or more. Not a test (minutes, and GB of disk): a benchmark.
#
# Usage: benches/bag_memory.sh [DIR] (default: a fresh folder under
# ${TMPDIR:-/tmp}, removed at the end; the bags need 2 x SIZE of disk).
# Environment: ACTIVECAL_BIN (default target/debug/activecal, built by
# `cargo build`: the dev profile is optimised), BAG_IMAGE_MB (default 2000:
# the images' megabytes), BAG_STORAGES (default "mcap sqlite3").
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
bin="${ACTIVECAL_BIN:-$root/target/debug/activecal}"
py="$root/.venv/bin/python"
image_mb="${BAG_IMAGE_MB:-2000}"
limit_mb=500
[ -x "$bin" ] || { echo "bag_memory: $bin is not built (cargo build)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "bag_memory: /usr/bin/time (GNU time) is needed" >&2; exit 2; }
if [ $# -ge 1 ]; then dir=$1; mkdir -p "$dir"; keep=1; else dir=$(mktemp -d); keep=0; fi
[ $keep = 1 ] || trap 'rm -rf "$dir"' EXIT
cd "$dir"
urdf="$root/fixtures/example-robot-data/ur5_robot.urdf"
"$py" -W ignore "$root/verify/python/truth.py" make --urdf "$urdf" --tip tool0 --seed 7 --out truth.json >/dev/null
"$py" -W ignore "$root/verify/python/truth.py" sensor-frames --truth truth.json --out nominal.yaml >/dev/null
"$bin" select --robot "$urdf" --frames nominal.yaml --pool random --count 2048 --pool-seed 7 \
  --n 30 --noise 5e-5 --seed 7 --out design.csv --force --json >/dev/null
status=0
for storage in ${BAG_STORAGES:-mcap sqlite3}; do
  bag="bag_$storage"
  rm -rf "$bag"
  start=$(date +%s)
  "$py" -W ignore "$root/verify/python/bag_truth.py" write --truth truth.json --design design.csv \
    --out "$bag" --storage "$storage" --joint-rate 1000 --image-mb "$image_mb" >/dev/null
  size=$(($(du -sb "$bag" | cut -f1) / 1000000))
  echo "bag_memory: $storage bag written by rosbags in $(($(date +%s) - start)) s: $size MB"
  /usr/bin/time -v -o time.txt "$bin" extract "$bag" --robot "$urdf" --frames nominal.yaml \
    --points /tracker --out "m_$storage.csv" --force --json >"extract_$storage.json"
  rss_kb=$(awk -F': ' '/Maximum resident set size/ {print $2}' time.txt)
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' time.txt)
  rests=$("$py" -c "import json,sys; r=json.load(open(sys.argv[1])); print(sum(1 for x in r['rests'] if x['left_out'] is None))" "extract_$storage.json")
  rss_mb=$((rss_kb / 1024))
  echo "bag_memory: $storage: activecal extract of $size MB: peak resident memory $rss_mb MB, wall $wall (m:ss), $rests rests kept"
  if [ "$rss_mb" -ge "$limit_mb" ]; then
    echo "bag_memory: $storage: peak $rss_mb MB is over the $limit_mb MB limit" >&2
    status=1
  fi
  rm -rf "$bag"
done
exit $status
