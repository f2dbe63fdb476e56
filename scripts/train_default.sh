#!/usr/bin/env bash
# Reproduces the default base detector models/lwd3d/detector.pt (models/MODEL_CARD.md) on a 2-core machine:
#   1. simulates the training set (urban 32 x 80 frames, highway 8 x 60 frames, HDL-64E) and a validation set
#      (urban, 2 x 50 frames, seeds never used for training or for the held-out test set of the model card);
#   2. trains both heads side by side, one torch thread each (config/detector/lwd3d_{center,anchor}.yaml);
#   3. runs each on the validation set (`ret3d detect` then `ret3d eval`) and installs the better one (mean of the
#      three classes' 3D AP R40 moderate) as models/lwd3d/detector.pt.
# Resumable: run it again after a stop and it continues from the last checkpoint (every 5 minutes); finished steps
# are skipped. About 75-90 minutes on the idle 2-core machine. Work goes to data/ and out/train_default/.
set -eo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
if [ ! -x build/devel/bin/ret3d ]; then scripts/setup.sh; fi
set +u
source scripts/env.sh
set -u
OUT=out/train_default
mkdir -p "$OUT" data models/lwd3d

simulate() {  # name config sequences frames seed
  if [ -f "data/$1/.done" ]; then return; fi
  rm -rf "data/$1"
  ret3d sim --config "$2" --out "data/$1" --sequences "$3" --frames "$4" --seed "$5" >"$OUT/$1.log" 2>&1
  touch "data/$1/.done"
}
simulate sim_train_urban config/sim/urban_street.yaml 32 80 1000
simulate sim_train_highway config/sim/highway.yaml 8 60 2000
simulate sim_val_urban config/sim/urban_street.yaml 2 50 5000

train() {  # head
  if [ -f "$OUT/$1.pt" ] && [ -f "$OUT/$1.done" ]; then return; fi
  ret3d train detector --data data/sim_train_urban data/sim_train_highway --config "config/detector/lwd3d_$1.yaml" \
    --out "$OUT/$1.pt" --threads 1 --resume >"$OUT/train_$1.log" 2>&1
  touch "$OUT/$1.done"
}
start=$(date +%s)
train center &
pid_center=$!
train anchor &
pid_anchor=$!
wait $pid_center
wait $pid_anchor
echo "training took $(( ($(date +%s) - start) / 60 )) min (this run)"

best=""
best_ap=-1
for head in center anchor; do
  mkdir -p "$OUT/val_$head"
  cp "$OUT/$head.pt" "$OUT/val_$head/detector.pt"
  ret3d detect --data data/sim_val_urban --models "$OUT/val_$head" --out "$OUT/val_$head/pred" --stages base \
    >"$OUT/val_$head/detect.log" 2>&1
  ret3d eval --gt data/sim_val_urban --pred "$OUT/val_$head/pred" --out "$OUT/val_$head/eval" \
    >"$OUT/val_$head/eval.log" 2>&1
  ap=$(python3 -c "
import json
m = json.load(open('$OUT/val_$head/eval/metrics.json'))
print(sum(m['kitti.%s.3d.R40.moderate' % c] for c in ('Car', 'Pedestrian', 'Cyclist')) / 3)")
  echo "$head head: mean 3D AP R40 moderate on the validation set $ap"
  if python3 -c "import sys; sys.exit(0 if $ap > $best_ap else 1)"; then best=$head; best_ap=$ap; fi
done
cp "$OUT/$best.pt" models/lwd3d/detector.pt
echo "default detector: the $best head (validation mean 3D AP R40 moderate $best_ap) -> models/lwd3d/detector.pt"
