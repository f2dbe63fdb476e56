#!/usr/bin/env bash
# The two-resolution detector (docs/RESULTS.md, "Long range"): the default
# model keeps its 0.25 m cells over a near field, and a second network on 0.5 m cells over x +-80, y +-48 m gives the
# boxes outside it (inference.far_field). The far network starts from models/lwd3d's weights
# (config/detector/lwd3d_anchor_far.yaml), then its score calibration is refitted, both are put in one folder
# (`ret3d train far-field`), IntraRM / InterRM are trained behind the pair, and the validation table, the six real
# frames and the cost are measured against the default. Resumable: every step leaves a marker in OUT.
#   scripts/experiments/far_field.sh
# Needs data/sim5_* (the fifth generation of the simulator; scripts/train_default.sh's commands with data/sim5_ names),
# data/real_unl_long (scripts/experiments/long_range.sh makes it) and the real scans (RET3D_SHARED_DATA).
# Environment: OUT (default out/far), NEAR (the near field, default -40,40,-24,24), RET3D_BIN (the binary that trains,
# default ret3d: a copy lets the tree be rebuilt meanwhile).
set -eo pipefail
cd "$(dirname "$0")/../.."
set +u
source scripts/env.sh
set -u
source scripts/experiments/refit_calibration.sh
OUT=${OUT:-out/far}
NEAR=${NEAR:--40,40,-24,24}
B=${RET3D_BIN:-ret3d}
REL=data/sim5_relation_urban
VAL=data/sim5_val_urban
mkdir -p "$OUT/models"
for d in data/sim5_train_urban data/sim5_train_highway $REL $VAL data/real_unl_long; do
  [ -d "$d" ] || { echo "far_field.sh: $d is missing" >&2; exit 1; }
done
TRAIN=(--data data/sim5_train_urban data/sim5_train_highway data/real_unl_long --data-weights 1 1 12
  --labels-cover all all all --gt-database data/gtdb/sim5_far.gtdb --threads 2 --resume)

# 1. The far network: 10 epochs from the default's weights on the 0.5 m cells.
[ -f data/gtdb/sim5_far.gtdb ] || $B train gtdb --data data/sim5_train_urban data/sim5_train_highway \
  --config config/detector/lwd3d_anchor_far.yaml --out data/gtdb/sim5_far.gtdb >"$OUT/gtdb.log" 2>&1
if [ ! -f "$OUT/far.done" ]; then
  $B train detector "${TRAIN[@]}" --config config/detector/lwd3d_anchor_far.yaml --init models/lwd3d/detector.pt \
    --init-other-cells --out "$OUT/far.pt" >"$OUT/train.log" 2>&1
  touch "$OUT/far.done"
fi

# 2. Its score calibration, refitted on the relation set over its whole grid (scripts/experiments/refit_calibration.sh).
if [ ! -f "$OUT/far_cal.done" ]; then
  refit_calibration config/detector/lwd3d_anchor_far.yaml "$OUT/far.pt" "$OUT/far_cal.pt" "$OUT" $REL "${TRAIN[@]}"
  touch "$OUT/far_cal.done"
fi

# 3. The pair as one folder, and the relation modules behind it.
if [ ! -f "$OUT/models.done" ]; then
  $B train far-field --near models/lwd3d/detector.pt --far "$OUT/far_cal.pt" --near-extent="$NEAR" \
    --out "$OUT/models" | tee "$OUT/far_field.log"
  $B train intra --data $REL --detector "$OUT/models/detector.pt" --score-threshold 0.3 \
    --config config/relation/intra_lwd3d_m1.yaml --sequences 0-9 --val-sequences 10-11 --threads 2 \
    --out "$OUT/models/intra_rm.pt" >"$OUT/train_intra.log" 2>&1
  $B train inter --data $REL --detector "$OUT/models/detector.pt" --score-threshold 0.3 \
    --intra-model "$OUT/models/intra_rm.pt" --tracker-config config/tracker_lwd3d.yaml \
    --config config/relation/inter_lwd3d.yaml --sequences 0-9 --val-sequences 10-11 --threads 2 \
    --out "$OUT/models/inter_rm.pt" >"$OUT/train_inter.log" 2>&1
  touch "$OUT/models.done"
fi

# 4. Validation (seeds 5000-5001 of the current simulator), whole pipeline and base detector: the default, the pair.
row() {  # name stages models
  local n=$1 stages=$2 m=$3
  [ -f "out/heldout/far_val_$n/eval/metrics.json" ] ||
    EVAL_DATA=$VAL scripts/experiments/eval_heldout.sh "$stages" "far_val_$n" --models "$m" >"$OUT/val_$n.log" 2>&1
  python3 - "out/heldout/far_val_$n" "$n" <<'PY'
import json, os, sys
o, n = sys.argv[1:]
m = json.load(open(o + "/eval/metrics.json"))
cells = [n, "%.2f / %.2f / %.2f" % tuple(m["kitti.%s.3d.R40.moderate" % c] for c in ("Car", "Pedestrian", "Cyclist")),
         "%.2f" % m["waymo.mean.L2.APH"],
         "%.2f / %.2f / %.2f" % tuple(m["waymo_range.Car.%s.L2.AP" % r] for r in ("0-30", "30-50", "50+"))]
if "mot.Car.MOTA" in m:
    m48 = json.load(open(o + "/eval_48m/metrics.json"))
    cells += ["%.2f / %.2f / %.2f" % tuple(m["mot.%s.MOTA" % c] for c in ("Car", "Pedestrian", "Cyclist")),
              "%.2f" % m48["mot.Car.MOTA"]]
print("| " + " | ".join(cells) + " |")
PY
}
echo "| | Car / Ped / Cyc 3D | L2 mAPH | Car L2 AP 0-30 / 30-50 / 50+ m | MOTA Car / Ped / Cyc | Car MOTA within 48 m |"
row default base,intra,track,inter models/lwd3d
row far base,intra,track,inter "$OUT/models"
row default_base base models/lwd3d
row far_base base "$OUT/models"

# 5. The six real frames, the same command for both.
for m in models/lwd3d "$OUT/models"; do
  n=$(basename "$(dirname "$m/x")")
  OUT_REAL=$OUT/real_$n
  OUT=$OUT_REAL DOCS=$OUT_REAL/docs scripts/experiments/real_scans.sh "$m" >"$OUT_REAL.log" 2>&1 || true
done
echo "cost: ret3d bench --data $VAL --stages base --models $OUT/models --baseline models/lwd3d --min-runs 100"
