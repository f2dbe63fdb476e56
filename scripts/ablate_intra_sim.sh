#!/usr/bin/env bash
# IntraRM on this package's detector, simulated data (Ret3D Tables 3, 5, 6 analogues):
#   trains every config/relation/intra_lwd3d*.yaml on the default detector's boxes and features over the relation
#   set (urban, seeds 3000-3011: sequences 0-9 train, 10-11 validation), then runs base + IntraRM on the held-out set
#   (scripts/eval_heldout.sh: urban seeds 9000-9004, 500 frames), prints one row per configuration and writes the
#   table between the intra-sim-ablation markers of docs/RESULTS.md.
#   scripts/ablate_intra_sim.sh [CONFIGS...]     (default: all; two trainings at a time, one thread each)
# Work files: out/ablate_intra_sim/. Needs models/lwd3d/detector.pt.
set -eo pipefail
cd "$(dirname "$0")/.."
set +u
source scripts/env.sh
set -u
OUT=out/ablate_intra_sim
DET=${DETECTOR:-models/lwd3d/detector.pt}
mkdir -p "$OUT"
CONFIGS=("$@")
if [ ${#CONFIGS[@]} -eq 0 ]; then
  CONFIGS=(intra_lwd3d intra_lwd3d_no_edge intra_lwd3d_r1 intra_lwd3d_r4 intra_lwd3d_m1 intra_lwd3d_m2 intra_lwd3d_m6)
fi
DATA=data/sim_relation_urban
if [ ! -f "$DATA/.done" ]; then
  rm -rf "$DATA"
  ret3d sim --config config/sim/urban_street.yaml --out "$DATA" --sequences 12 --frames 80 --seed 3000
  touch "$DATA/.done"
fi

train() {  # config
  [ -f "$OUT/$1.pt" ] && return
  ret3d train intra --data "$DATA" --detector "$DET" --detections-cache "$OUT/dets.cache" \
    --config "config/relation/$1.yaml" --sequences 0-9 --val-sequences 10-11 --out "$OUT/$1.pt" --threads 1 --quiet \
    >"$OUT/$1.train.log" 2>&1
}
# The detector's outputs once (the cache), then the trainings two at a time.
train "${CONFIGS[0]}"
for ((i = 1; i < ${#CONFIGS[@]}; i += 2)); do
  train "${CONFIGS[$i]}" &
  if ((i + 1 < ${#CONFIGS[@]})); then train "${CONFIGS[$((i + 1))]}"; fi
  wait
done

[ -f out/heldout/base/eval/metrics.json ] || scripts/eval_heldout.sh base base --detector-model "$DET" >/dev/null
for c in "${CONFIGS[@]}"; do
  [ -f "out/heldout/$c/eval/metrics.json" ] ||
    scripts/eval_heldout.sh base,intra "$c" --detector-model "$DET" --intra-model "$OUT/$c.pt" >/dev/null
done
python3 - "${CONFIGS[@]}" <<'PY'
import json, sys
rows = ["base"] + sys.argv[1:]
what = {"base": "base detector alone", "intra_lwd3d": "r 2 m, m 4 (shipped)", "intra_lwd3d_no_edge": "no edges (r 2 m, m 4)",
        "intra_lwd3d_r1": "r 1 m, m 4", "intra_lwd3d_r4": "r 4 m, m 4", "intra_lwd3d_m1": "r 2 m, m 1",
        "intra_lwd3d_m2": "r 2 m, m 2", "intra_lwd3d_m6": "r 2 m, m 6"}
out = ["| configuration | graph | Car 3D @0.7 | Ped 3D @0.5 | Cyc 3D @0.5 | L2 mAP | L2 mAPH | train s |",
       "| --- | --- | --- | --- | --- | --- | --- | --- |"]
for r in rows:
    m = json.load(open("out/heldout/%s/eval/metrics.json" % r))
    secs = ""
    if r != "base":
        for line in open("out/ablate_intra_sim/%s.train.log" % r):
            if "IntraRM trained:" in line:
                secs = line.split(" in ")[1].split(" s")[0]
    out.append("| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %s |" % (r, what.get(r, ""), m["kitti.Car.3d.R40.moderate"],
               m["kitti.Pedestrian.3d.R40.moderate"], m["kitti.Cyclist.3d.R40.moderate"], m["waymo.mean.L2.AP"],
               m["waymo.mean.L2.APH"], secs))
print("\n".join(out))
path = "docs/RESULTS.md"
text = open(path).read()
begin, end = "<!-- intra-sim-ablation:begin -->", "<!-- intra-sim-ablation:end -->"
if begin in text and end in text:
    a, b = text.index(begin) + len(begin), text.index(end)
    open(path, "w").write(text[:a] + "\n" + "\n".join(out) + "\n" + text[b:])
    print("written to " + path)
PY
