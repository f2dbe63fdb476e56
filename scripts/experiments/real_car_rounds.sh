#!/usr/bin/env bash
# One or two more epochs of the default detector aimed at real cars, four ways (docs/RESULTS.md, "Real scans", tried and
# dropped), each with its score calibration refitted as scripts/train_default.sh's dark_round does:
#   tracked  today's simulator's training sets + training_extra + the 37 unlabelled real scans, the 22 consecutive
#            ones carrying the cars the whole pipeline tracked over them (`ret3d autolabel`, then
#            scripts/real_negatives.py --tracks; config/detector/lwd3d_anchor_tracked.yaml);
#   cabin    today's simulator's training sets (car windows returning from the cabin) + training_extra, no real scans
#            (config/detector/lwd3d_anchor_cabin.yaml);
#   hills    the cabin round's sets plus hilly streets (config/sim/hills.yaml), at half the learning rate
#            (config/detector/lwd3d_anchor_hills.yaml);
#   hills2   the same sets, hills weighted twice, two epochs at the dark round's rate with every scene moved up or
#            down by up to 0.6 m (config/detector/lwd3d_anchor_hills2.yaml).
#   scripts/experiments/real_car_rounds.sh tracked|cabin|hills|hills2
# Writes OUT/<round>/models/{detector,intra_rm,inter_rm}.pt (IntraRM and InterRM are models/lwd3d's), to be measured
# with `scripts/experiments/real_scans.sh OUT/<round>/models`. Environment: OUT (default out/real_car_rounds).
set -eo pipefail
cd "$(dirname "$0")/../.."
set +u; source scripts/env.sh; set -u
source scripts/simulate_once.sh
source scripts/real_folder.sh
source scripts/experiments/refit_calibration.sh
ROUND=${1:?tracked, cabin, hills or hills2}
OUT=${OUT:-out/real_car_rounds}
DATA_DIR=${RET3D_SHARED_DATA:-$PWD/../shared/data}
W=$OUT/$ROUND
mkdir -p "$W/models"
simulate_once data/sim8_train_urban config/sim/urban_street.yaml 32 80 1000 "$OUT/sim8_train_urban.log"
simulate_once data/sim8_train_highway config/sim/highway.yaml 8 60 2000 "$OUT/sim8_train_highway.log"
simulate_once data/sim8_train_queue config/sim/queue.yaml 8 80 2500 "$OUT/sim8_train_queue.log"
simulate_once data/sim8_relation_urban config/sim/urban_street.yaml 12 80 3000 "$OUT/sim8_relation_urban.log"
[ -f data/gtdb/sim8_train.gtdb ] || ret3d train gtdb --data data/sim8_train_urban data/sim8_train_highway \
  data/sim8_train_queue --config config/detector/lwd3d_anchor_robust.yaml --out data/gtdb/sim8_train.gtdb \
  >"$OUT/gtdb.log" 2>&1
# The simulated sets (weight 1, labels all around; hills2 weighs the hills twice), then training_extra (camera view).
SIM=(data/sim8_train_urban data/sim8_train_highway data/sim8_train_queue)
WEIGHTS=(1 1 1)
if [ "$ROUND" = hills ] || [ "$ROUND" = hills2 ]; then
  simulate_once data/sim8_train_hills config/sim/hills.yaml 16 80 1500 "$OUT/sim8_train_hills.log"
  SIM+=(data/sim8_train_hills)
  if [ "$ROUND" = hills2 ]; then WEIGHTS+=(2); else WEIGHTS+=(1); fi
fi
TRAIN=(--data "${SIM[@]}" "$DATA_DIR/kitti_object/training_extra")
WEIGHTS+=(40)
COVER=("${SIM[@]/*/all}" camera)
if [ "$ROUND" = tracked ]; then
  # The 37 real scans in an object layout (the 22 consecutive ones as frames 900000-900021), labelled from the default
  # detector's boxes and the pipeline's tracks over the 22.
  REAL=data/real_unl_tracked
  if [ ! -d "$REAL/training/label_2" ]; then
    real_folder "$REAL"
    ret3d autolabel --data "$DATA_DIR/unlabeled_scans" --out "$W/auto22" --score-threshold 0.1 >"$W/autolabel.log" 2>&1
    ret3d detect --data "$REAL" --models models/lwd3d --stages base --score-threshold 0.05 --out "$W/real_pred" \
      >"$W/real_pred.log" 2>&1
    python3 scripts/real_negatives.py "$REAL" "$W/real_pred" --tracks "$W/auto22/training/label_02/0000.txt" \
      --tracks-first-frame 900000 >"$W/real_labels.log"
  fi
  TRAIN+=("$REAL"); WEIGHTS+=(12); COVER+=(all)
fi
CFG=config/detector/lwd3d_anchor_$ROUND.yaml
OPTS=("${TRAIN[@]}" --data-weights "${WEIGHTS[@]}" --labels-cover "${COVER[@]}" --gt-database data/gtdb/sim8_train.gtdb
  --threads 2 --resume)
[ -f "$W/trained.done" ] || { ret3d train detector "${OPTS[@]}" --config "$CFG" --init models/lwd3d/detector.pt \
  --out "$W/detector_nocal.pt" >"$W/train.log" 2>&1; touch "$W/trained.done"; }
CAR_CALIBRATION="--iou 0.5" refit_calibration "$CFG" "$W/detector_nocal.pt" "$W/models/detector.pt" "$W" \
  data/sim8_relation_urban "${OPTS[@]}"
ln -sfn "$PWD/models/lwd3d/intra_rm.pt" "$W/models/intra_rm.pt"
ln -sfn "$PWD/models/lwd3d/inter_rm.pt" "$W/models/inter_rm.pt"
echo "real_car_rounds.sh $ROUND: $W/models (calibration: $(tail -n 2 "$W/calib_car.log" | head -n 1))"
