#!/usr/bin/env bash
# IntraRM on this package's detector, simulated data (Ret3D Tables 3, 5, 6 analogues):
#   trains every config/relation/intra_lwd3d*.yaml on the default detector's boxes and features over the relation
#   set (urban, seeds 3000-3011: sequences 0-9 train, 10-11 validation), then runs base + IntraRM on the held-out set
#   (scripts/experiments/eval_heldout.sh: urban seeds 9000-9004, 500 frames), prints one row per configuration and
#   writes the table between the intra-sim-ablation markers of docs/RESULTS.md.
#   scripts/experiments/ablate_intra_sim.sh [CONFIGS...]     (default: all; two trainings at a time, one thread each)
# Environment: DETECTOR (default models/lwd3d/detector.pt); RELATION_DATA (the relation set, default
# data/sim_relation_urban, simulated when missing with seeds 3000-3011); HELDOUT_SEED (another held-out set, as
# scripts/experiments/eval_heldout.sh: a fresh one for a new detector).
# Work files: out/ablate_intra_sim/.
set -eo pipefail
cd "$(dirname "$0")/../.."
set +u
source scripts/env.sh
set -u
OUT=out/ablate_intra_sim
DET=${DETECTOR:-models/lwd3d/detector.pt}
DATA=${RELATION_DATA:-data/sim_relation_urban}
# Results of another detector, relation set or held-out set are stale: start afresh when one changed.
stamp="$(md5sum "$DET" | cut -c1-32) $DATA ${HELDOUT_SEED:-9000}"
if [ "$(cat "$OUT/detector.md5" 2>/dev/null)" != "$stamp" ]; then rm -rf "$OUT" out/heldout/base out/heldout/intra_lwd3d*; fi
mkdir -p "$OUT"
echo "$stamp" >"$OUT/detector.md5"
CONFIGS=("$@")
if [ ${#CONFIGS[@]} -eq 0 ]; then
  CONFIGS=(intra_lwd3d intra_lwd3d_no_edge intra_lwd3d_r1 intra_lwd3d_r4 intra_lwd3d_m1 intra_lwd3d_m2 intra_lwd3d_m6)
fi
source scripts/simulate_once.sh
simulate_once "$DATA" config/sim/urban_street.yaml 12 80 3000

train() {  # config
  [ -f "$OUT/$1.pt" ] && return
  # Taught on the boxes scoring >= 0.3, run on the published ones (>= 0.5), as scripts/train_default.sh.
  ret3d train intra --data "$DATA" --detector "$DET" --score-threshold 0.3 --detections-cache "$OUT/dets.cache" \
    --config "config/relation/$1.yaml" --sequences 0-9 --val-sequences 10-11 --out "$OUT/$1.pt" --threads 1 --quiet \
    >"$OUT/$1.train.log" 2>&1
}
source scripts/experiments/two_at_a_time.sh
two_at_a_time train "${CONFIGS[@]}"

[ -f out/heldout/base/eval/metrics.json ] ||
  scripts/experiments/eval_heldout.sh base base --detector-model "$DET" >/dev/null
for c in "${CONFIGS[@]}"; do
  [ -f "out/heldout/$c/eval/metrics.json" ] ||
    scripts/experiments/eval_heldout.sh base,intra "$c" --detector-model "$DET" --intra-model "$OUT/$c.pt" >/dev/null
done
python3 scripts/experiments/results_table.py intra "$OUT" "${CONFIGS[@]}"
