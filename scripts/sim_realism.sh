#!/usr/bin/env bash
# Realism figure of the simulator (docs/sim_realism.png, discussed in docs/SIMULATOR.md): histograms of range,
# intensity and points per ring, and points on cars against distance, for simulated urban HDL-64E scans and the real
# KITTI scans of ../shared/data (read in place, never copied). Usage: scripts/sim_realism.sh [RET3D_BINARY]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
RET3D=${1:-$ROOT/build/devel/bin/ret3d}
DATA=${RET3D_SHARED_DATA:-$ROOT/../shared/data}
OUT=${OUT:-$ROOT/out/sim_realism}
CONFIG=$ROOT/config/sim/urban_street.yaml
[ -d "$DATA/unlabeled_scans" ] || { echo "real scans not found under $DATA (set RET3D_SHARED_DATA)" >&2; exit 1; }
mkdir -p "$OUT"
if [ -z "${PLOT_ONLY:-}" ]; then  # PLOT_ONLY=1: replot the .dat files already in $OUT
"$RET3D" sim --config "$CONFIG" --out "$OUT/sim" --sequences 3 --frames 20 --seed 1
"$RET3D" sim --config "$CONFIG" --stats "$OUT/sim" --stats-out "$OUT/sim" --frames 60 | tee "$OUT/summary.txt"
"$RET3D" sim --config "$CONFIG" --stats "$DATA/unlabeled_scans" --stats-out "$OUT/real_scans" --frames 60 | tee -a "$OUT/summary.txt"
"$RET3D" sim --config "$CONFIG" --stats "$DATA/kitti_object" --stats-out "$OUT/real_object" --frames 60 | tee -a "$OUT/summary.txt"
fi

gnuplot <<GP
set terminal png size 1600,1100
set termoption noenhanced
set output "$ROOT/docs/sim_realism.png"
set multiplot layout 2,2 title "ret3d sim (urban_street, HDL-64E, 60 frames) vs real KITTI HDL-64E scans (22 unlabeled + 4 kitti_object)"
set grid
set key top right
set style data lines
set title "range"
set xlabel "range (m), 1 m bins"
set ylabel "fraction of points"
set logscale y
set xrange [0:100]
plot "$OUT/sim_range.dat" u 1:3 lw 2 lc rgb "#d62728" t "simulated", \
     "$OUT/real_scans_range.dat" u 1:3 lw 2 lc rgb "#1f77b4" t "real (unlabeled_scans)", \
     "$OUT/real_object_range.dat" u 1:3 lw 1 dt 2 lc rgb "#2ca02c" t "real (kitti_object)"
unset logscale y
set title "intensity"
set xlabel "intensity (reflectance), 0.02 bins"
set xrange [0:1]
plot "$OUT/sim_intensity.dat" u 1:3 lw 2 lc rgb "#d62728" t "simulated", \
     "$OUT/real_scans_intensity.dat" u 1:3 lw 2 lc rgb "#1f77b4" t "real (unlabeled_scans)", \
     "$OUT/real_object_intensity.dat" u 1:3 lw 1 dt 2 lc rgb "#2ca02c" t "real (kitti_object)"
set title "points per ring (real: ring estimated from elevation)"
set xlabel "ring (0 = lowest beam)"
set ylabel "points per frame"
set xrange [-1:64]
plot "$OUT/sim_rings.dat" u 1:2 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#d62728" t "simulated", \
     "$OUT/real_scans_rings.dat" u 1:2 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#1f77b4" t "real (unlabeled_scans)", \
     "$OUT/real_object_rings.dat" u 1:2 w lines lw 1 dt 2 lc rgb "#2ca02c" t "real (kitti_object)"
set title "points inside each labelled car box"
set xlabel "distance (m)"
set ylabel "points in box"
set logscale y
set xrange [0:80]
set yrange [1:20000]
set arrow from 10,1 to 10,20000 nohead dt 3 lc rgb "gray"
set arrow from 20,1 to 20,20000 nohead dt 3 lc rgb "gray"
set arrow from 40,1 to 40,20000 nohead dt 3 lc rgb "gray"
plot "$OUT/sim_cars.dat" u 1:(\$2+1) w points pt 7 ps 0.5 lc rgb "#d62728" t "simulated (all cars, 360 deg)", \
     "$OUT/real_object_cars.dat" u 1:(\$2+1) w points pt 9 ps 1.6 lc rgb "#2ca02c" t "real kitti_object (camera view)"
unset multiplot
GP
echo "wrote $ROOT/docs/sim_realism.png"
