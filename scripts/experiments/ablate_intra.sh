#!/usr/bin/env bash
# IntraRM on real detections: trains each configuration of config/relation/intra_*.yaml on the PointRCNN boxes of
# KITTI tracking sequences 0001-0015, refines the boxes of 0016-0020 with it, evaluates KITTI 3D AP (R40) with
# `ret3d eval`, and writes the table between the intra-ablation markers of docs/RESULTS.md.
#
#   scripts/experiments/ablate_intra.sh [BUILD_DIR]
#   (default build/; configs to run: CONFIGS="intra_rm intra_no_edge ...")
#
# Needs the shared KITTI-derived data (../shared/data, or RET3D_SHARED_DATA). Work files go to out/ablate_intra/.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
BUILD="${1:-$ROOT/build}"
RET3D="$BUILD/devel/bin/ret3d"
SHARED="${RET3D_SHARED_DATA:-$ROOT/../shared/data}"
DATA="$SHARED/kitti_tracking"
DETS="$DATA/detections/pointrcnn"
OUT="$ROOT/out/ablate_intra"
CONFIGS="${CONFIGS:-intra_rm intra_boxes intra_no_edge intra_r1 intra_r4 intra_m1 intra_m2 intra_m6}"
TRAIN_SEQ="${TRAIN_SEQ:-1-15}"
TEST_SEQ="${TEST_SEQ:-16-20}"
THREADS="${THREADS:-2}"
[ -x "$RET3D" ] || { echo "ablate_intra: $RET3D not built" >&2; exit 1; }
[ -d "$DETS" ] || { echo "ablate_intra: $DETS missing (set RET3D_SHARED_DATA)" >&2; exit 1; }
mkdir -p "$OUT"

# AP row "name | Car | Pedestrian | Cyclist | mean | train s | ms/frame" from a report's metrics.json.
ap_row() {  # name report_dir extra_cells
  python3 - "$1" "$2/metrics.json" "$3" <<'PY'
import json, sys
name, path, extra = sys.argv[1], sys.argv[2], sys.argv[3]
m = json.load(open(path))
aps = [m["kitti.%s.3d.R40.moderate" % cls] for cls in ("Car", "Pedestrian", "Cyclist")]
print("| %s | %.2f | %.2f | %.2f | %.2f | %s |" % (name, aps[0], aps[1], aps[2], sum(aps) / 3, extra))
PY
}

run_eval() {  # pred_dir report_dir
  "$RET3D" eval --gt "$DATA" --pred "$1" --out "$2" --metric kitti --sequences "$TEST_SEQ" --threads "$THREADS" \
    > "$2.log" 2>&1
}

ROWS="$OUT/rows.md"
: > "$ROWS"
echo "== base (PointRCNN boxes through the same conversions)"
"$RET3D" detect --data "$DATA" --detections "$DETS" --stages none --sequences "$TEST_SEQ" --out "$OUT/base/pred"
run_eval "$OUT/base/pred" "$OUT/base/report"
ap_row "PointRCNN (base)" "$OUT/base/report" "- | -" | tee -a "$ROWS"
for cfg in $CONFIGS; do
  echo "== $cfg"
  start=$(date +%s)
  "$RET3D" train intra --data "$DATA" --detections "$DETS" --sequences "$TRAIN_SEQ" \
    --config "$ROOT/config/relation/$cfg.yaml" --out "$OUT/$cfg/model.pt" --threads "$THREADS" --quiet \
    > "$OUT/$cfg.train.log" 2>&1
  secs=$(( $(date +%s) - start ))
  "$RET3D" detect --data "$DATA" --detections "$DETS" --stages intra --intra-model "$OUT/$cfg/model.pt" \
    --sequences "$TEST_SEQ" --out "$OUT/$cfg/pred" --threads "$THREADS" | tee "$OUT/$cfg.detect.log"
  ms=$(sed -n 's/.*IntraRM \([0-9.]*\) ms per frame.*/\1/p' "$OUT/$cfg.detect.log")
  run_eval "$OUT/$cfg/pred" "$OUT/$cfg/report"
  ap_row "+IntraRM $cfg" "$OUT/$cfg/report" "$secs | ${ms:-?}" | tee -a "$ROWS"
done

# Replace the table between the markers in docs/RESULTS.md.
RESULTS="$ROOT/docs/RESULTS.md"
python3 - "$RESULTS" "$ROWS" "$TRAIN_SEQ" "$TEST_SEQ" <<'PY'
import sys, datetime
path, rows, train, test = sys.argv[1:5]
begin, end = "<!-- intra-ablation:begin -->", "<!-- intra-ablation:end -->"
table = ("Trained on PointRCNN boxes of sequences %s, evaluated on %s (KITTI 3D AP, R40, moderate; %s UTC; "
         "`scripts/experiments/ablate_intra.sh`).\n\n"
         % (train, test, datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"))
         + "| configuration | Car | Pedestrian | Cyclist | mean | train s | IntraRM ms/frame |\n"
         + "| --- | --- | --- | --- | --- | --- | --- |\n" + open(rows).read())
text = open(path).read() if __import__("os").path.exists(path) else "# Results\n"
if begin in text and end in text:
    text = text[:text.index(begin) + len(begin)] + "\n" + table + text[text.index(end):]
else:
    text += "\n" + begin + "\n" + table + end + "\n"
open(path, "w").write(text)
PY
echo "table written to $RESULTS"
