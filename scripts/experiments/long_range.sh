#!/usr/bin/env bash
# The long-range candidate (docs/RESULTS.md, "Long range"): the default detector's
# network on x +-80, y +-48 m in 1/3 m cells, started from models/lwd3d's weights, then its score calibration refitted
# and IntraRM / InterRM trained behind it, and the validation table against the default. Resumable: every step leaves
# a marker in OUT and a training resumes from its checkpoint.
#   scripts/experiments/long_range.sh [STAGES]
# STAGES default "1 2": config/detector/lwd3d_anchor_long.yaml (4 epochs from the default's weights), then
# lwd3d_anchor_long2.yaml (10 more); "1" stops after the first.
# Needs the unlabelled real scans (RET3D_SHARED_DATA or ../shared/data) and data/sim4_* (scripts/train_default.sh).
# Environment: OUT (default out/long). Writes OUT/models/{detector,intra_rm,inter_rm}.pt and OUT/val/*/ (the table).
set -eo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
set +u
source scripts/env.sh
set -u
source scripts/experiments/refit_calibration.sh
OUT=${OUT:-out/long}
STAGES=${1:-1 2}
DATA_DIR=${RET3D_SHARED_DATA:-$ROOT/../shared/data}
GRID=-80,80,-48,48
mkdir -p "$OUT/models"
for d in data/sim4_train_urban data/sim4_train_highway data/sim4_relation_urban data/sim4_val_urban data/real_unl2; do
  [ -d "$d" ] || { echo "long_range.sh: $d is missing (scripts/train_default.sh makes it)" >&2; exit 1; }
done

# The 37 unlabelled real scans labelled as background by the default detector run over the whole long grid
# (scripts/real_negatives.py), so that nothing beyond 48 m is taught as background unseen.
REAL=data/real_unl_long
if [ ! -d "$REAL/training/label_2" ]; then
  mkdir -p "$REAL/training"
  cp -a data/real_unl2/training/velodyne data/real_unl2/training/calib "$REAL/training/"
  ret3d detect --data "$REAL" --models models/lwd3d --stages base --score-threshold 0.05 --grid-extent=$GRID \
    --out "$OUT/real_pred" >"$OUT/real_pred.log" 2>&1
  python3 scripts/real_negatives.py "$REAL" "$OUT/real_pred" >"$OUT/real_labels.log"
fi
[ -f data/gtdb/sim4_long.gtdb ] || ret3d train gtdb --data data/sim4_train_urban data/sim4_train_highway \
  --config config/detector/lwd3d_anchor_long.yaml --out data/gtdb/sim4_long.gtdb >"$OUT/gtdb.log" 2>&1
TRAIN=(--data data/sim4_train_urban data/sim4_train_highway "$REAL" --data-weights 1 1 12 --labels-cover all all all
  --gt-database data/gtdb/sim4_long.gtdb --threads 2 --resume)

model=""
for s in $STAGES; do
  case $s in
    1) name=long; cfg=config/detector/lwd3d_anchor_long.yaml
       init=(--init models/lwd3d/detector.pt --init-other-cells) ;;
    2) name=long2; cfg=config/detector/lwd3d_anchor_long2.yaml; init=(--init "$OUT/long.pt") ;;
    *) echo "long_range.sh: unknown stage $s" >&2; exit 1 ;;
  esac
  if [ ! -f "$OUT/$name.done" ]; then
    ret3d train detector "${TRAIN[@]}" --config $cfg "${init[@]}" --out "$OUT/$name.pt" >"$OUT/train_$name.log" 2>&1
    touch "$OUT/$name.done"
  fi
  model=$OUT/$name.pt
done

# Score calibration refitted for these weights on the relation set (as scripts/train_default.sh does), the model
# saved again with it (the train command once more with --resume: no step), then the relation modules behind it.
name=$(basename "$model" .pt)
if [ ! -f "$OUT/${name}_cal.done" ]; then
  rel=data/sim4_relation_urban
  refit_calibration config/detector/lwd3d_anchor_$name.yaml "$model" "$OUT/${name}_cal.pt" "$OUT" $rel "${TRAIN[@]}"
  cp "$OUT/${name}_cal.pt" "$OUT/models/detector.pt"
  ret3d train intra --data $rel --detector "$OUT/models/detector.pt" --score-threshold 0.3 \
    --config config/relation/intra_lwd3d_m1.yaml --sequences 0-9 --val-sequences 10-11 --threads 2 \
    --out "$OUT/models/intra_rm.pt" >"$OUT/train_intra.log" 2>&1
  ret3d train inter --data $rel --detector "$OUT/models/detector.pt" --score-threshold 0.3 \
    --intra-model "$OUT/models/intra_rm.pt" --tracker-config config/tracker_lwd3d.yaml \
    --config config/relation/inter_lwd3d.yaml --sequences 0-9 --val-sequences 10-11 --threads 2 \
    --out "$OUT/models/inter_rm.pt" >"$OUT/train_inter.log" 2>&1
  touch "$OUT/${name}_cal.done"
fi

# Validation (seeds 5000-5001), whole pipeline (scripts/experiments/eval_heldout.sh on the validation set, into
# out/heldout/long_val_<name>): the default, the default over the long grid, the candidate.
D=data/sim4_val_urban
val() {  # name models [extra ret3d detect options]
  local n=$1 m=$2
  shift 2
  EVAL_DATA=$D scripts/experiments/eval_heldout.sh base,intra,track,inter "long_val_$n" --models "$m" "$@" \
    >"$OUT/val_$n.log" 2>&1
  python3 - "out/heldout/long_val_$n" "$n" <<'PY'
import json, sys
o, n = sys.argv[1:]
m = json.load(open(o + "/eval/metrics.json"))
m48 = json.load(open(o + "/eval_48m/metrics.json"))
print("| %s | %.2f / %.2f / %.2f | %.2f | %.2f / %.2f / %.2f | %.2f / %.2f / %.2f | %.2f |" % (
    n, m["kitti.Car.3d.R40.moderate"], m["kitti.Pedestrian.3d.R40.moderate"], m["kitti.Cyclist.3d.R40.moderate"],
    m["waymo.mean.L2.APH"], m["waymo_range.Car.0-30.L2.AP"], m["waymo_range.Car.30-50.L2.AP"],
    m["waymo_range.Car.50+.L2.AP"], m["mot.Car.MOTA"], m["mot.Pedestrian.MOTA"], m["mot.Cyclist.MOTA"],
    m48["mot.Car.MOTA"]))
PY
}
echo "| | Car / Ped / Cyc 3D | L2 mAPH | Car L2 AP 0-30 / 30-50 / 50+ m | MOTA Car / Ped / Cyc | Car MOTA within 48 m |"
val default models/lwd3d
val default_wide models/lwd3d --grid-extent=$GRID
val "$name" "$OUT/models"
echo "cost: ret3d bench --data $D --stages base --models $OUT/models --baseline models/lwd3d --min-runs 60"
