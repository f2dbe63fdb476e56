#!/usr/bin/env bash
# The first command to run. Sets up and builds (scripts/setup.sh), simulates a short urban drive as a bag (ret3d sim:
# 150 HDL-64E scans at 10 Hz with ground truth, once), replays it in real time through the whole pipeline with the
# default models (launch/replay.launch: detector, IntraRM, tracker, InterRM and markers in one nodelet manager, with
# simulated time), records /objects, scores them against the bag's ground truth (ret3d eval) and prints a summary.
#
# Usage: scripts/demo.sh [--rviz] [--bag FILE] [--models DIR] [--rate R] [--out DIR] [--no-setup] [--screenshot PNG]
#   --rviz        watch it in rviz (needs a display); headless without it
#   --bag FILE    replay your own bag instead (PointCloud2 on /points, tf from `odom` to the cloud's frame); scored
#                 only when it has /ground_truth/objects (ret3d/Object3DArray)
#   --models DIR  folder with detector.pt, intra_rm.pt, inter_rm.pt (default models/lwd3d); without intra_rm.pt or
#                 inter_rm.pt that stage is switched off, and the summary says so
#   --rate R      playback rate (default 1: real time)
#   --out DIR     where the outputs go (default out/demo): objects.bag, replay.log, report/, summary.txt
#   --no-setup    skip scripts/setup.sh (the package is built already)
#   --screenshot PNG  rviz on a virtual display (Xvfb), photographed halfway through the replay (docs/demo_rviz.png
#                 was made so, with --rate 0.5: rviz's software rendering needs the cores too)
# The replay runs on a ROS master of its own (a free port), so a roscore already running is left alone.
# Exits non-zero, saying why, when a step fails.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

RVIZ=false BAG="" MODELS="$ROOT/models/lwd3d" RATE=1.0 OUT="$ROOT/out/demo" SETUP=true SHOT=""
usage() { sed -n '7,19p' "$0" | sed 's/^# \{0,1\}//'; }
while (($#)); do
  case "$1" in
    --rviz) RVIZ=true ;;
    --bag) BAG=$(realpath "${2:?--bag needs a file}"); shift ;;
    --models) MODELS=$(realpath "${2:?--models needs a folder}"); shift ;;
    --rate) RATE=${2:?--rate needs a number}; shift ;;
    --out) OUT=$(realpath -m "${2:?--out needs a folder}"); shift ;;
    --no-setup) SETUP=false ;;
    --screenshot) SHOT=$(realpath -m "${2:?--screenshot needs a file}"); shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "demo: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
say() { echo "demo: $*"; }
fail() { echo "demo: $*" >&2; exit 1; }

if [[ -z "$SHOT" ]] && $RVIZ && [[ -z "${DISPLAY:-}" ]]; then fail "--rviz needs a display (DISPLAY is not set)"; fi
if [[ -n "$BAG" && ! -f "$BAG" ]]; then fail "no bag at $BAG"; fi

if $SETUP; then scripts/setup.sh; fi
# ROS's setup scripts read unset variables: source them without nounset.
set +u
source scripts/env.sh
set -u
command -v ret3d >/dev/null || fail "the ret3d command is not built (run scripts/setup.sh)"
mkdir -p "$OUT"

# The models. The detector is needed; a relation stage without its model is switched off.
DETECTOR="$MODELS/detector.pt"
[[ -f "$DETECTOR" ]] || fail "no detector model at $DETECTOR: models/lwd3d/detector.pt comes with the package \
(scripts/train_default.sh trains it again), or give --models DIR"
INTRA=true INTER=true STAGES="detector"
if [[ -f "$MODELS/intra_rm.pt" ]]; then STAGES+=", IntraRM"; else
  INTRA=false; say "no IntraRM model ($MODELS/intra_rm.pt): IntraRM switched off for this run"; fi
STAGES+=", tracker"
if [[ -f "$MODELS/inter_rm.pt" ]]; then STAGES+=", InterRM"; else
  INTER=false; say "no InterRM model ($MODELS/inter_rm.pt): InterRM switched off (tracked boxes published unrefined)"; fi
$INTRA || STAGES+="; IntraRM off (no model)"
$INTER || STAGES+="; InterRM off (no model)"

# The drive: simulated once (about 20 s on 2 cores), then reused.
if [[ -z "$BAG" ]]; then
  BAG="$ROOT/data/demo/0000.bag"
  if [[ ! -f "$ROOT/data/demo/.done" ]]; then
    say "simulating a 15 s urban drive (150 HDL-64E scans, ground truth) into data/demo ..."
    rm -rf "$ROOT/data/demo"
    ret3d sim --config config/sim/urban_street.yaml --out data/demo --sequences 1 --frames 150 --seed 777 --bag \
      >"$OUT/sim.log" 2>&1 || { tail -20 "$OUT/sim.log" >&2; fail "simulation failed (log: $OUT/sim.log)"; }
    touch "$ROOT/data/demo/.done"
  fi
fi

# For --screenshot: rviz on a virtual display of its own, with software OpenGL.
if [[ -n "$SHOT" ]]; then
  command -v Xvfb >/dev/null && command -v import >/dev/null || fail "--screenshot needs Xvfb and imagemagick"
  for SCREEN in $(seq 90 120); do [[ -e /tmp/.X$SCREEN-lock || -e /tmp/.X11-unix/X$SCREEN ]] || break; done
  Xvfb ":$SCREEN" -screen 0 1280x720x24 -nolisten tcp >"$OUT/xvfb.log" 2>&1 &
  XVFB=$!
  trap 'kill "$XVFB" 2>/dev/null || true' EXIT
  export DISPLAY=":$SCREEN" LIBGL_ALWAYS_SOFTWARE=1
  RVIZ=true
fi

# The replay, on a master of its own; ROS logs under OUT.
PORT=$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$PORT" ROS_HOME="$OUT/ros_home"
DURATION=$(rosbag info --yaml --key=duration "$BAG")
LIMIT=$(python3 -c "print(int(120 + float('$DURATION') / float('$RATE')))")
rm -f "$OUT/objects.bag" "$OUT/objects.bag.active"
say "replaying $BAG ($(printf %.1f "$DURATION") s at rate $RATE) through $STAGES; log: $OUT/replay.log"
if [[ -n "$SHOT" ]]; then
  # The player starts about 4 s after the launch (model loading, replay.launch's delay); then half the drive.
  (sleep "$(python3 -c "print(5 + float('$DURATION') / float('$RATE') / 2)")"
   import -display "$DISPLAY" -window root "$SHOT" >>"$OUT/xvfb.log" 2>&1) &
  SHOOTER=$!
fi
rc=0
timeout --signal=INT --kill-after=20 "$LIMIT" roslaunch ret3d replay.launch bag:="$BAG" record:="$OUT/objects.bag" \
  rate:="$RATE" rviz:="$RVIZ" intra:="$INTRA" inter:="$INTER" detector_model:="$DETECTOR" \
  intra_model:="$MODELS/intra_rm.pt" inter_model:="$MODELS/inter_rm.pt" >"$OUT/replay.log" 2>&1 || rc=$?
# roslaunch ends with 0 when a required node dies too: what it said and what it recorded decide.
if grep -q "refuses to start" "$OUT/replay.log"; then
  sed 's/\x1b\[[0-9;]*m//g' "$OUT/replay.log" | grep -o "\[FATAL\].*refuses to start.*" >&2
  fail "a pipeline stage refused to start (log: $OUT/replay.log)"
fi
if ((rc == 124)); then fail "the replay did not end within $LIMIT s (log: $OUT/replay.log)"; fi
if ((rc != 0)) || [[ ! -f "$OUT/objects.bag" ]]; then
  sed 's/\x1b\[[0-9;]*m//g' "$OUT/replay.log" | grep -E "ERROR|FATAL|died|Error" | head -20 >&2 || true
  fail "the replay failed (roslaunch exit status $rc; log: $OUT/replay.log)"
fi

if [[ -n "$SHOT" ]]; then
  wait "$SHOOTER" && [[ -f "$SHOT" ]] || fail "no screenshot taken (log: $OUT/xvfb.log)"
  say "rviz screenshot: $SHOT"
fi

# The scores, when the bag has ground truth.
SCORES=()
if [[ $(rosbag info --yaml --key=topics "$BAG") == *"/ground_truth/objects"* ]]; then
  say "scoring /objects against the bag's ground truth (ret3d eval) ..."
  rm -rf "$OUT/report"
  ret3d eval --gt "$BAG" --pred "$OUT/objects.bag" --out "$OUT/report" --metric kitti,mot >"$OUT/eval.log" 2>&1 ||
    { tail -20 "$OUT/eval.log" >&2; fail "evaluation failed (log: $OUT/eval.log)"; }
  SCORES=(--metrics "$OUT/report/metrics.json" --report "${OUT#"$ROOT"/}/report/report.md")
else
  say "the bag has no /ground_truth/objects: no scores"
fi

echo
python3 scripts/demo_summary.py --input "${BAG#"$ROOT"/}" --record "${OUT#"$ROOT"/}/objects.bag" --stages "$STAGES" "${SCORES[@]}" |
  tee "$OUT/summary.txt"
