#!/usr/bin/env bash
# Realism figure of the simulator (docs/sim_realism.png, discussed in docs/SIMULATOR.md): histograms of range,
# intensity, points per ring, height above the ground, height scatter per BEV cell and points per occupied BEV cell,
# and points on cars against distance, for simulated urban HDL-64E scans and the real KITTI scans of ../shared/data
# (read in place, never copied), with the Wasserstein-1 distance of each statistic (ret3d sim --compare) in the panel
# titles and in $OUT/sim_w1.txt.
# Usage: [BEFORE_REV=<git revision>] scripts/experiments/sim_realism.sh [RET3D_BINARY]
#   BEFORE_REV: also simulate with the presets (config/sim/urban_street.yaml, config/sensors/hdl64e.yaml) of that
#   revision, with this binary (knobs a preset does not name are off), and plot and compare it as "before".
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
RET3D=${1:-$ROOT/build/devel/bin/ret3d}
DATA=${RET3D_SHARED_DATA:-$ROOT/../shared/data}
OUT=${OUT:-$ROOT/out/sim_realism}
CONFIG=$ROOT/config/sim/urban_street.yaml
[ -d "$DATA/unlabeled_scans" ] || { echo "real scans not found under $DATA (set RET3D_SHARED_DATA)" >&2; exit 1; }
# The real scans the distances are measured against: unlabelled only (the labelled kitti_object frames are a
# validation set; they appear in the figure as before, never in the distances).
REAL=("$DATA/unlabeled_scans")
[ -d "$DATA/kitti_object/unlabeled/velodyne" ] && REAL+=("$DATA/kitti_object/unlabeled/velodyne")
mkdir -p "$OUT"
simulate() {  # TAG CONFIG
  "$RET3D" sim --config "$2" --out "$OUT/$1" --sequences 3 --frames 20 --seed 1 | tail -n 9
  "$RET3D" sim --config "$2" --stats "$OUT/$1" --stats-out "$OUT/$1" --frames 60 | tee -a "$OUT/summary.txt"
  "$RET3D" sim --compare "$OUT/$1" "$OUT/real" | tee "$OUT/$1_w1.txt"
}
if [ -z "${PLOT_ONLY:-}" ]; then  # PLOT_ONLY=1: replot the .dat files already in $OUT
  : > "$OUT/summary.txt"
  "$RET3D" sim --config "$CONFIG" --stats "${REAL[@]}" --stats-out "$OUT/real" --frames 60 | tee -a "$OUT/summary.txt"
  "$RET3D" sim --config "$CONFIG" --stats "$DATA/kitti_object" --stats-out "$OUT/real_object" --frames 60 | tee -a "$OUT/summary.txt"
  if [ -n "${BEFORE_REV:-}" ]; then
    mkdir -p "$OUT/before_root/config/sim" "$OUT/before_root/config/sensors"
    for f in config/sim/urban_street.yaml config/sensors/hdl64e.yaml; do
      git -C "$ROOT" show "$BEFORE_REV:$f" > "$OUT/before_root/$f"
    done
    simulate before "$OUT/before_root/config/sim/urban_street.yaml"
  fi
  simulate sim "$CONFIG"
fi

# "name W1" lines -> a title suffix per statistic: "W1 after" or "W1 before -> after".
w1() {
  local a b
  a=$(awk -v s="$1" '$1 == s {print $2}' "$OUT/sim_w1.txt")
  if [ -f "$OUT/before_w1.txt" ]; then
    b=$(awk -v s="$1" '$1 == s {print $2}' "$OUT/before_w1.txt")
    echo "W1 to real: before $b, now $a"
  else
    echo "W1 to real: $a"
  fi
}
BEFORE_PLOT=""
[ -f "$OUT/before_range.dat" ] && BEFORE_PLOT=1
before() {  # FILE COLUMNS: a gnuplot plot clause for the "before" curve, or nothing
  [ -n "$BEFORE_PLOT" ] && echo ", \"$OUT/before_$1.dat\" u $2 lw 1 lc rgb \"#ff9896\" t \"simulated before\""
  return 0
}

curves() {  # NAME: the simulated (now and before), real and kitti_object curves of one histogram (fraction column)
  echo "\"$OUT/sim_$1.dat\" u 1:3 lw 2 lc rgb \"#d62728\" t \"simulated\" $(before "$1" 1:3), \
    \"$OUT/real_$1.dat\" u 1:3 lw 2 lc rgb \"#1f77b4\" t \"real (unlabelled)\", \
    \"$OUT/real_object_$1.dat\" u 1:3 lw 1 dt 2 lc rgb \"#2ca02c\" t \"real (kitti_object)\""
}

gnuplot <<GP
set terminal png size 2000,1500
set termoption noenhanced
set output "$ROOT/docs/sim_realism.png"
set multiplot layout 3,3 title "ret3d sim (urban_street, HDL-64E, 60 frames) vs real KITTI HDL-64E scans (unlabeled_scans 22 + kitti_object/unlabeled 15; kitti_object 6 labelled dashed)"
set grid
set key top right
set style data lines
set title "range\n$(w1 range) m"
set xlabel "range (m), 1 m bins"
set ylabel "fraction of points"
set logscale y
set xrange [0:100]
plot $(curves range)
unset logscale y
set title "intensity: $(w1 intensity)\nfraction of zero-intensity returns: $(w1 zero)"
set xlabel "intensity (reflectance), 0.02 bins"
set xrange [0:1]
plot $(curves intensity)
set title "points per ring, real: estimated from elevation\n$(w1 rings) rings"
set xlabel "ring (0 = lowest beam)"
set ylabel "points per frame"
set xrange [-1:64]
plot "$OUT/sim_rings.dat" u 1:2 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#d62728" t "simulated" $(before rings 1:2), \
     "$OUT/real_rings.dat" u 1:2 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#1f77b4" t "real (unlabelled)", \
     "$OUT/real_object_rings.dat" u 1:2 w lines lw 1 dt 2 lc rgb "#2ca02c" t "real (kitti_object)"
set title "height above a flat ground (z + 1.73 m)\n$(w1 height) m"
set xlabel "height (m), 0.1 m bins"
set ylabel "fraction of points"
set logscale y
set xrange [-1:5]
plot $(curves height)
set title "height std-dev per 0.5 m BEV cell with >= 5 points, < 40 m\n$(w1 scatter) m"
set xlabel "std-dev of z in the cell (m), 0.05 m bins (last bin: the rest)"
set xrange [0:2]
plot $(curves scatter)
set title "points > 0.3 m up per occupied 0.5 m BEV cell, 10-40 m\n$(w1 cellpoints) points"
set xlabel "points in the cell (last bin: 50 or more)"
set xrange [0:51]
plot $(curves cellpoints)
set title "points inside each labelled car box"
set xlabel "distance (m)"
set ylabel "points in box"
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
