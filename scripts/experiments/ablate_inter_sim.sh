#!/usr/bin/env bash
# InterRM on this package's detector and IntraRM, simulated data (Ret3D Table 4 analogue and the history length N):
#   trains InterRM for every history length N (config/relation/inter_lwd3d.yaml with max_history N) and every
#   positional encoding (config/relation/inter_lwd3d_pe_*.yaml, N = the shipped one) on the default models' boxes
#   over the relation set (urban, seeds 3000-3011: sequences 0-9 train, 10-11 validation), then runs
#   base + IntraRM + the pipeline's tracker + InterRM on the held-out set (scripts/experiments/eval_heldout.sh: urban
#   seeds 9000-9004, 500 frames) and times tracker + InterRM for 50 tracks with full histories (`ret3d bench`).
#   Prints one row per configuration and writes the tables between the inter-sim-history and inter-sim-pe markers
#   of docs/RESULTS.md, and the Table 3 analogue (table3-sim markers) with the shipped history length.
#   scripts/experiments/ablate_inter_sim.sh            (two trainings at a time, one thread each; ~1 min per training)
#   HISTORIES="1 10 30" scripts/experiments/ablate_inter_sim.sh
# Work files: out/ablate_inter_sim/. Needs models/lwd3d/{detector,intra_rm}.pt.
set -eo pipefail
cd "$(dirname "$0")/../.."
set +u
source scripts/env.sh
set -u
OUT=${OUT:-out/ablate_inter_sim}
MODELS=${MODELS:-models/lwd3d}
HISTORIES=${HISTORIES-1 5 10 30 60 100}
PES=${PES-temporal spatial}
TRACKER=config/tracker_lwd3d.yaml          # InterRM trains on confidently tracked objects
TRACKER_EVAL=config/tracker_lwd3d_pipeline.yaml  # and runs behind the pipeline's tracker
# Results of other models are stale: start afresh when the detector or IntraRM changed.
stamp=$(md5sum "$MODELS/detector.pt" "$MODELS/intra_rm.pt" | cut -c1-32 | tr -d '\n')
if [ "$(cat "$OUT/models.md5" 2>/dev/null)" != "$stamp" ]; then rm -rf "$OUT" out/heldout/sim_inter_* out/heldout/sim_intra_track; fi
mkdir -p "$OUT/configs"
echo "$stamp" >"$OUT/models.md5"
source scripts/simulate_once.sh
DATA=data/sim_relation_urban
simulate_once "$DATA" config/sim/urban_street.yaml 12 80 3000

NAMES=()
for n in $HISTORIES; do
  # The shipped config with another history length (a `base:` path absolute, as the file lives under $OUT).
  printf 'base: %s\nmodel:\n  max_history: %s\n' "$PWD/config/relation/inter_lwd3d.yaml" "$n" >"$OUT/configs/inter_h$n.yaml"
  NAMES+=("inter_h$n")
done
for pe in $PES; do
  printf 'base: %s\n' "$PWD/config/relation/inter_lwd3d_pe_$pe.yaml" >"$OUT/configs/inter_pe_$pe.yaml"
  NAMES+=("inter_pe_$pe")
done

train() {  # name
  [ -f "$OUT/$1.pt" ] && return
  ret3d train inter --data "$DATA" --detector "$MODELS/detector.pt" --detections-cache "$OUT/dets.cache" \
    --intra-model "$MODELS/intra_rm.pt" --tracker-config "$TRACKER" --config "$OUT/configs/$1.yaml" \
    --sequences 0-9 --val-sequences 10-11 --out "$OUT/$1.pt" --threads 1 --quiet >"$OUT/$1.train.log" 2>&1
}
source scripts/experiments/two_at_a_time.sh
two_at_a_time train "${NAMES[@]}"

MODEL_FLAGS=(--detector-model "$MODELS/detector.pt" --intra-model "$MODELS/intra_rm.pt")
[ -f out/heldout/sim_intra_track/eval/metrics.json ] ||
  scripts/experiments/eval_heldout.sh base,intra,track sim_intra_track "${MODEL_FLAGS[@]}" \
    --tracker-config "$TRACKER_EVAL" >/dev/null
for c in "${NAMES[@]}"; do
  [ -f "out/heldout/sim_$c/eval/metrics.json" ] ||
    scripts/experiments/eval_heldout.sh base,intra,track,inter "sim_$c" "${MODEL_FLAGS[@]}" \
      --inter-model "$OUT/$c.pt" --tracker-config "$TRACKER_EVAL" >/dev/null
  [ -f "$OUT/$c.bench.json" ] ||
    ret3d bench --stages track,inter --models "$MODELS" --inter-model "$OUT/$c.pt" --tracker-config "$TRACKER_EVAL" \
      --objects 50 --json "$OUT/$c.bench.json" >"$OUT/$c.bench.log" 2>&1
done
python3 scripts/experiments/results_table.py inter "$OUT" "${NAMES[@]}"
# Table 3 analogue with the shipped history length (config/relation/inter_lwd3d.yaml), when its rows are all there
# (base and + IntraRM come from scripts/experiments/ablate_intra_sim.sh).
shipped=$(sed -n 's/^ *max_history: *\([0-9]*\).*/\1/p' config/relation/inter_lwd3d.yaml)
if [ -f out/heldout/base/eval/metrics.json ] && [ -f out/heldout/intra_lwd3d_m1/eval/metrics.json ] &&
  [ -f "out/heldout/sim_inter_h$shipped/eval/metrics.json" ]; then
  python3 scripts/experiments/results_table.py table3 "inter_h$shipped"
fi
