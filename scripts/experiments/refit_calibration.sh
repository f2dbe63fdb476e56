# Sourced by the experiment scripts (long_range.sh, far_field.sh): refits a detector's score calibration for its
# weights on a relation set, as scripts/train_default.sh does for the default, and saves the model again with it.
#   refit_calibration CONFIG MODEL CALIBRATED_MODEL WORKDIR RELATION_DATA [ret3d train detector options...]
# CONFIG is the model's training YAML; its score_calibration is stripped, the model run over RELATION_DATA (network
# score >= 0.3), scripts/fit_score_calibration.py fitted per class (Pedestrian and Cyclist at IoU 0.5 without the
# shape terms), WORKDIR/calibrated.yaml written, and MODEL copied with its checkpoints to CALIBRATED_MODEL and saved
# with that YAML (the train command once more with --resume and the given options: no step). Uses $RET3D_BIN or ret3d;
# CAR_CALIBRATION holds further options of the Car fit (e.g. "--iou 0.5", as scripts/train_default.sh fits the default).
refit_calibration() {
  local cfg=$1 model=$2 cal=$3 work=$4 rel=$5
  shift 5
  local bin=${RET3D_BIN:-ret3d}
  python3 scripts/calibration_config.py strip "$cfg" "$work/nocal.yaml"
  $bin detect --data "$rel" --detector-model "$model" --detector-config "$work/nocal.yaml" --stages base \
    --score-threshold 0.3 --out "$work/calib_pred" >"$work/calib_detect.log" 2>&1
  python3 scripts/fit_score_calibration.py --gt "$rel" --pred "$work/calib_pred" --class Car ${CAR_CALIBRATION:-} \
    >"$work/calib_car.log"
  for c in Pedestrian Cyclist; do
    python3 scripts/fit_score_calibration.py --gt "$rel" --pred "$work/calib_pred" --class $c --iou 0.5 --no-shape \
      >"$work/calib_$c.log"
  done
  python3 scripts/calibration_config.py insert "$work/nocal.yaml" "$work/calibrated.yaml" "$work/calib_car.log" \
    "$work/calib_Pedestrian.log" "$work/calib_Cyclist.log"
  for f in "" .ckpt .ckpt.optim .ckpt.state; do cp "$model$f" "$cal$f"; done
  $bin train detector "$@" --config "$work/calibrated.yaml" --out "$cal" >"$work/calib_save.log" 2>&1
}
