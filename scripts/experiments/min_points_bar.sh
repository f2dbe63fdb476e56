#!/usr/bin/env bash
# The long-range bar in the Waymo Open Dataset's terms: the whole pipeline on the simulated validation drives (urban
# seeds 5000-5001, labels to 80 m), scored by `ret3d eval --min-points K` for K = 0, 5, 10, 20 (a label holding
# fewer than K returns is not counted). Prints one table row: Car MOTA per K, Car 3D AP, LEVEL_2 mAPH, false boxes per
# frame. Extra options go to `ret3d detect` (e.g. --grid-extent=-80,80,-48,48, --detector-config FILE,
# --score-threshold S --tracker-config FILE).
# Usage: scripts/experiments/min_points_bar.sh NAME [ret3d detect options...]   (output in out/min_points/NAME)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
cd "$ROOT"
NAME=${1:?usage: min_points_bar.sh NAME [ret3d detect options...]}
shift
set +u
source scripts/env.sh
set -u
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
# shellcheck source=../simulate_once.sh
source scripts/simulate_once.sh
VAL=data/sim8_val_urban
OUT=out/min_points/$NAME
mkdir -p "$OUT"
simulate_once "$VAL" config/sim/urban_street.yaml 2 50 5000 "$OUT/sim.log"
ret3d detect --data "$VAL" --models models/lwd3d --stages base,intra,track,inter --out "$OUT/pred" "$@" \
  >"$OUT/detect.log" 2>&1
for K in 0 5 10 20; do
  ret3d eval --gt "$VAL" --pred "$OUT/pred" --out "$OUT/eval_$K" --kitti-recall exact --min-points "$K" \
    >"$OUT/eval_$K.log" 2>&1
done
python3 - "$OUT" "$NAME" <<'PY'
import json
import sys

out, name = sys.argv[1:3]
m = {k: json.load(open('%s/eval_%d/metrics.json' % (out, k))) for k in (0, 5, 10, 20)}
mota = ' | '.join('%.2f' % m[k]['mot.Car.MOTA'] for k in (0, 5, 10, 20))
print('| %s | %s | %.2f | %.2f | %.2f |' % (name, mota, m[0]['kitti.Car.3d.R40.moderate'], m[0]['waymo.mean.L2.APH'],
                                         m[0]['kitti.false_boxes_per_frame']))
PY
