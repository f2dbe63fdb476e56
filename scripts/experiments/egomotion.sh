#!/usr/bin/env bash
# The ego motion from scans (core/scan_matching.h) by the hand-written ICP and PCL's GICP side by side, one run on the
# same scans (docs/RESULTS.md, "Ego motion from the scans"): two simulated urban drives of 100 frames with exact ego
# poses (errors, drift, time), then the 22 consecutive real scans of ../shared/data/unlabeled_scans (time, agreement).
# Usage: scripts/experiments/egomotion.sh
# Environment: RET3D (default build/devel/bin/ret3d), RET3D_SHARED_DATA (default ../shared/data), OUT (default
#   out/egomotion; the simulated drives go to data/simreg).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
cd "$ROOT"
RET3D=${RET3D:-$ROOT/build/devel/bin/ret3d}
DATA=${RET3D_SHARED_DATA:-$ROOT/../shared/data}
OUT=${OUT:-$ROOT/out/egomotion}
[ -x "$RET3D" ] || { echo "egomotion.sh: no ret3d binary at $RET3D (build ret3d_cli, or set RET3D)" >&2; exit 1; }
mkdir -p "$OUT"

if [ ! -d data/simreg/training/pose ]; then
  "$RET3D" sim --config config/sim/urban_street.yaml --out data/simreg --sequences 2 --frames 100 --seed 9100
fi
"$RET3D" egomotion --data data/simreg --matchers icp,gicp --per-frame "$OUT/sim.csv" | tee "$OUT/sim.txt"

if [ -d "$DATA/unlabeled_scans" ]; then
  "$RET3D" egomotion --data "$DATA/unlabeled_scans" --matchers icp,gicp --per-frame "$OUT/real.csv" \
    | tee "$OUT/real.txt"
else
  echo "egomotion.sh: real scans skipped: no $DATA/unlabeled_scans (set RET3D_SHARED_DATA)" >&2
fi
