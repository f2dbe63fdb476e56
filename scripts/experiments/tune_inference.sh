#!/usr/bin/env bash
# Chooses the detector's inference options on a tuning set (never on the held-out test set): simulates it once
# (urban, HDL-64E, 8 x 60 frames, seeds 5100-5107, used nowhere else), then runs `ret3d detect --stages base` and
# `ret3d eval` on it for every pair of box-voting IoU
# (inference.nms_voting_iou) and IoU-score power (inference.iou_score_power) below and prints the mean of the three
# classes' 3D AP R40 moderate (the criterion scripts/train_default.sh selects models by), best last.
#   scripts/experiments/tune_inference.sh MODEL CONFIG [VOTING_LIST] [POWER_LIST]
#   scripts/experiments/tune_inference.sh out/train_default/anchor_stage2.pt config/detector/lwd3d_anchor_stage2.yaml
# CONFIG: the model's YAML; only its inference values are varied. Work goes to out/tune_inference/.
set -eo pipefail
cd "$(dirname "$0")/../.."
MODEL=${1:?model file}
CONFIG=${2:?detector config YAML of the model}
VOTING=${3:-0 0.3 0.5 0.65}
POWERS=${4:-0 0.3 0.5 0.7}
set +u
source scripts/env.sh
set -u
source scripts/simulate_once.sh
DATA=data/sim_tune_urban
simulate_once "$DATA" config/sim/urban_street.yaml 8 60 5100 /dev/null
OUT=out/tune_inference
mkdir -p "$OUT"
: >"$OUT/results.txt"
for v in $VOTING; do
  for p in $POWERS; do
    name="vote${v}_power${p}"
    python3 - "$CONFIG" "$v" "$p" >"$OUT/$name.yaml" <<'PY'
import re, sys
text, v, p = open(sys.argv[1]).read(), sys.argv[2], sys.argv[3]
text = re.sub(r"(?m)^  (nms_voting_iou|iou_score_power):.*\n", "", text)
text = re.sub(r"(?m)^(  nms_iou:.*\n)", r"\g<1>  nms_voting_iou: %s\n  iou_score_power: %s\n" % (v, p), text)
sys.stdout.write(text)
PY
    ret3d detect --data "$DATA" --stages base --detector-model "$MODEL" --detector-config "$OUT/$name.yaml" \
      --out "$OUT/$name/pred" >"$OUT/$name.detect.log" 2>&1
    ret3d eval --gt "$DATA" --pred "$OUT/$name/pred" --out "$OUT/$name/eval" --metric kitti >"$OUT/$name.eval.log" 2>&1
    python3 - "$OUT/$name/eval/metrics.json" "$v" "$p" >>"$OUT/results.txt" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
ap = [m["kitti.%s.3d.R40.moderate" % c] for c in ("Car", "Pedestrian", "Cyclist")]
print("%.2f voting %s power %s (Car %.2f, Pedestrian %.2f, Cyclist %.2f)" % (sum(ap) / 3, sys.argv[2], sys.argv[3], *ap))
PY
    tail -1 "$OUT/results.txt"
  done
done
echo "best (mean 3D AP R40 moderate on $DATA):"
sort -n "$OUT/results.txt" | tail -1
