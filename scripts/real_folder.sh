# Sourced by the scripts that train on the unlabelled real scans: real_folder DIR makes DIR an object layout of
# symlinks to the 37 unlabelled scans of $DATA_DIR (the consecutive ones 000000-000021 as frames 900000-900021), each
# with the calibration of KITTI's 2011-09-26 recordings (kitti_tracking's 0001.txt, the values of
# kitti::defaultCalibration(); scripts/real_negatives.py reads it to bring the detector's boxes back to the LiDAR).
real_folder() {
  local dir=$1 f fr calib
  calib=$(realpath "$DATA_DIR/kitti_tracking/training/calib/0001.txt")
  mkdir -p "$dir/training/velodyne" "$dir/training/calib"
  for f in "$DATA_DIR"/kitti_object/unlabeled/velodyne/*.bin "$DATA_DIR"/unlabeled_scans/*.bin; do
    fr=$(basename "$f" .bin)
    [[ "$f" == */unlabeled_scans/* ]] && fr=$(printf '9%05d' $((10#$fr)))
    ln -sfn "$(realpath "$f")" "$dir/training/velodyne/$fr.bin"
    ln -sfn "$calib" "$dir/training/calib/$fr.txt"
  done
}
