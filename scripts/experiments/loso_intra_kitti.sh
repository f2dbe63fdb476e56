#!/usr/bin/env bash
# How stable is IntraRM's gain on real PointRCNN boxes across splits? Cross-validation over KITTI tracking sequences
# 0001-0020: for each fold, trains IntraRM (config/relation/intra_rm.yaml, as models/kitti_pointrcnn/intra_rm.pt) on
# the other sequences, then scores the held-out fold's PointRCNN boxes three ways (base = unchanged boxes through the
# same conversions, + the fold's IntraRM, + the shipped intra_rm.pt, which was trained on 0001-0015) and evaluates
# KITTI 3D AP R40 moderate with `ret3d eval`. scripts/experiments/loso_intra_kitti_summary.py then writes a table per
# fold, the mean / std / sign count of the gain per class, and a pooled evaluation of all held-out predictions at once.
# A measurement only: nothing is tuned.
#
#   scripts/experiments/loso_intra_kitti.sh
#   FOLDS="1-4 5-8 9-12 13-16 17-20" scripts/experiments/loso_intra_kitti.sh
#   (default: leave-one-sequence-out, 1 .. 20)
#
# Env: RET3D (binary, default build/devel/bin/ret3d), RET3D_SHARED_DATA (default ../shared/data), THREADS (1),
# FOLDS (space-separated --sequences specs), CONFIG (IntraRM YAML, default config/relation/intra_rm.yaml; e.g. another
# seed to see the training noise), OUT (default out/loso_intra_kitti; fold_*/ work folders, summary.md for the default
# folds, summary_<K>folds.md otherwise). Resumable: steps whose results exist are skipped.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
RET3D="${RET3D:-$ROOT/build/devel/bin/ret3d}"
SHARED="${RET3D_SHARED_DATA:-$ROOT/../shared/data}"
DATA="$SHARED/kitti_tracking"
DETS="$DATA/detections/pointrcnn"
CONFIG="${CONFIG:-$ROOT/config/relation/intra_rm.yaml}"
SHIPPED="$ROOT/models/kitti_pointrcnn/intra_rm.pt"
SHIPPED_TRAIN="1-15"   # the sequences the shipped model was trained on (its MODEL_CARD.md)
OUT="${OUT:-$ROOT/out/loso_intra_kitti}"
THREADS="${THREADS:-1}"
DEFAULT_FOLDS="$(seq -s ' ' 1 20)"
FOLDS="${FOLDS:-$DEFAULT_FOLDS}"
[ -x "$RET3D" ] || { echo "loso_intra_kitti: $RET3D not built (set RET3D)" >&2; exit 1; }
[ -d "$DETS" ] || { echo "loso_intra_kitti: $DETS missing (set RET3D_SHARED_DATA)" >&2; exit 1; }
[ -f "$SHIPPED" ] || { echo "loso_intra_kitti: $SHIPPED missing" >&2; exit 1; }
mkdir -p "$OUT"

expand() {  # "1-4,7" -> one sequence number a line
  local part
  for part in ${1//,/ }; do
    if [[ $part == *-* ]]; then seq "${part%-*}" "${part#*-}"; else echo "$part"; fi
  done
}

# The other sequences of 1-20, comma-separated.
complement() {
  local held s out=""
  held=" $(expand "$1" | tr '\n' ' ') "
  for s in $(seq 1 20); do [[ $held == *" $s "* ]] || out="$out,$s"; done
  echo "${out#,}"
}

detect_eval() {  # fold_dir name sequences stage-args...
  local dir=$1 name=$2 seqs=$3
  shift 3
  [ -f "$dir/eval_$name/metrics.json" ] && return 0
  rm -rf "$dir/pred_$name" "$dir/eval_$name"
  nice -n 10 "$RET3D" detect --data "$DATA" --detections "$DETS" --sequences "$seqs" --threads "$THREADS" \
    --out "$dir/pred_$name" "$@" > "$dir/detect_$name.log" 2>&1
  nice -n 10 "$RET3D" eval --gt "$DATA" --pred "$dir/pred_$name" --sequences "$seqs" --metric kitti \
    --threads "$THREADS" --out "$dir/eval_$name" > "$dir/eval_$name.log" 2>&1
}

start_all=$(date +%s)
for fold in $FOLDS; do
  dir="$OUT/fold_${fold//,/_}"
  train_seqs="$(complement "$fold")"
  mkdir -p "$dir"
  echo "== fold $fold (train on $train_seqs)"
  if [ ! -f "$dir/train.secs" ]; then
    start=$(date +%s)
    rm -rf "$dir/intra_rm.pt" "$dir/intra_rm.pt.ckpt"
    nice -n 10 "$RET3D" train intra --data "$DATA" --detections "$DETS" --sequences "$train_seqs" --config "$CONFIG" \
      --threads "$THREADS" --quiet --out "$dir/intra_rm.pt" > "$dir/train.log" 2>&1
    echo $(( $(date +%s) - start )) > "$dir/train.secs"
  fi
  detect_eval "$dir" base "$fold" --stages none
  detect_eval "$dir" intra "$fold" --stages intra --intra-model "$dir/intra_rm.pt"
  detect_eval "$dir" shipped "$fold" --stages intra --intra-model "$SHIPPED"
done

# All held-out predictions evaluated together: each sequence scored by the model that did not see it.
if [ "$FOLDS" = "$DEFAULT_FOLDS" ]; then scheme=loso; summary="$OUT/summary.md"
else scheme="k$(echo $FOLDS | wc -w)"; summary="$OUT/summary_$(echo $FOLDS | wc -w)folds.md"; fi
all_seqs="$(echo $FOLDS | tr ' ' ',')"
pooled="$OUT/pooled_$scheme"
for name in base intra shipped; do
  if [ ! -f "$pooled/eval_$name/metrics.json" ]; then
    rm -rf "$pooled/pred_$name" "$pooled/eval_$name"
    mkdir -p "$pooled/pred_$name"
    for fold in $FOLDS; do cp "$OUT/fold_${fold//,/_}/pred_$name"/*.txt "$pooled/pred_$name/"; done
    nice -n 10 "$RET3D" eval --gt "$DATA" --pred "$pooled/pred_$name" --sequences "$all_seqs" --metric kitti \
      --threads "$THREADS" --out "$pooled/eval_$name" > "$pooled/eval_$name.log" 2>&1
  fi
done

/usr/bin/python3 "$ROOT/scripts/experiments/loso_intra_kitti_summary.py" --out "$OUT" --pooled "$pooled" \
  --labels "$DATA/training/label_02" --shipped-train "$SHIPPED_TRAIN" --summary "$summary" --config "$CONFIG" \
  --folds $FOLDS
echo "done in $(( $(date +%s) - start_all )) s; summary: $summary"
