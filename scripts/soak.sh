#!/usr/bin/env bash
# The soak: a bag replayed in a loop through the nodelets (`ret3d bench --bag BAG --loop-frames N`, one
# manager process, at the bag's rate) with the manager's resident memory, open file descriptors, threads and the
# latencies sampled every --every clouds; then the plot of the samples (gnuplot, as scripts/experiments/sim_realism.sh)
# and the acceptance checks: memory from frame 1000 to the end grows by < 5 %, the descriptor count stays the same, the
# end-to-end p95 of the last 1000 frames is at most 10 % above the first 1000's.
# Usage: scripts/soak.sh [--bag FILE] [--frames N] [--every N] [--load N] [--out DIR] [-- BENCH ARGS...]
#   --bag FILE   the drive (default data/demo/0000.bag, made by scripts/demo.sh)
#   --frames N   clouds played in all (default 10000: about 17 minutes at 10 Hz)
#   --every N    clouds per sample (default 500)
#   --load N     cores kept busy meanwhile (default 0)
#   --out DIR    soak.json, soak.tsv, soak.log and soak.png go there (default out/soak)
#   BENCH ARGS   passed on to `ret3d bench` (e.g. --models DIR, --stages base,track)
# PLOT_ONLY=1: redraw the plot of the soak.tsv already in --out, without running the bench.
# Exits 0 when every check passes, 1 when one fails, 2 on a usage or run error.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BAG="$ROOT/data/demo/0000.bag" FRAMES=10000 EVERY=500 LOAD=0 OUT="$ROOT/out/soak"
usage() { sed -n '7,14p' "$0" | sed 's/^# \{0,1\}//'; }
while (($#)); do
  case "$1" in
    --bag) BAG=$(realpath "${2:?--bag needs a file}"); shift ;;
    --frames) FRAMES=${2:?--frames needs a number}; shift ;;
    --every) EVERY=${2:?--every needs a number}; shift ;;
    --load) LOAD=${2:?--load needs a number}; shift ;;
    --out) OUT=$(realpath -m "${2:?--out needs a folder}"); shift ;;
    --) shift; break ;;
    -h|--help) usage; exit 0 ;;
    *) echo "soak: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
[[ -n "${PLOT_ONLY:-}" || -f "$BAG" ]] || { echo "soak: no bag at $BAG (scripts/demo.sh simulates data/demo/0000.bag; or give --bag)" >&2; exit 2; }
command -v gnuplot >/dev/null || { echo "soak: gnuplot is missing (scripts/setup.sh installs gnuplot-nox)" >&2; exit 2; }
# ROS's setup scripts read unset variables: source them without nounset.
set +u
source "$ROOT/scripts/env.sh"
set -u
mkdir -p "$OUT"

if [[ -z "${PLOT_ONLY:-}" ]]; then
  rm -f "$OUT/soak.json" "$OUT/soak.tsv"
  set +e
  ret3d bench --bag "$BAG" --loop-frames "$FRAMES" --soak-every "$EVERY" --load "$LOAD" --json "$OUT/soak.json" "$@" \
    2>&1 | tee "$OUT/soak.log"
  RC=${PIPESTATUS[0]}
  set -e
  [[ $RC -eq 0 && -f "$OUT/soak.tsv" ]] || { echo "soak: the bench failed (log: $OUT/soak.log)" >&2; exit 2; }
else
  [[ -f "$OUT/soak.tsv" && -f "$OUT/soak.log" ]] || { echo "soak: PLOT_ONLY: no soak.tsv and soak.log in $OUT" >&2; exit 2; }
  FRAMES=$(tail -n 1 "$OUT/soak.tsv" | cut -f 1)
fi

# The checks' lines of the log as the plot's subtitle.
CHECKS=$(grep '^soak check:' "$OUT/soak.log" | sed 's/^soak check: //; s/"/\\"/g' | awk '{printf "%s\\n", $0}')
gnuplot <<GP
set terminal png size 1200,1100
set termoption noenhanced
set output "$OUT/soak.png"
set multiplot layout 3,1 title "ret3d soak: $(basename "$BAG") looped for $FRAMES frames through the nodelets (one manager), sampled every $EVERY\n$CHECKS"
set grid
set key top left
set xlabel "frame"
set xrange [0:$FRAMES]
set title "resident memory of the manager process (VmRSS)"
set ylabel "MB"
plot "$OUT/soak.tsv" u 1:3 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#1f77b4" t "VmRSS"
set title "open file descriptors and threads of the manager process"
set ylabel "count"
set yrange [0:*]
set key bottom right
plot "$OUT/soak.tsv" u 1:4 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#2ca02c" t "fds", \
     "" u 1:5 w linespoints pt 5 ps 0.6 lw 2 lc rgb "#9467bd" t "threads"
set title "latency per window of $EVERY frames (end-to-end: cloud stamp to the last stage's output); the machine's load"
set ylabel "ms"
set y2label "1-minute load average (2 cores)"
set key top right
set y2range [0:*]
set y2tics
plot "$OUT/soak.tsv" u 1:7 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#1f77b4" t "end-to-end p50", \
     "" u 1:8 w linespoints pt 7 ps 0.6 lw 2 lc rgb "#d62728" t "end-to-end p95", \
     "" u 1:9 w lines lw 1 dt 2 lc rgb "#d62728" t "end-to-end max", \
     "" u 1:11 w linespoints pt 5 ps 0.6 lw 1 lc rgb "#ff7f0e" t "detector p95", \
     "" u 1:14 axes x1y2 w lines lw 1 lc rgb "#7f7f7f" t "machine load (right axis)"
unset multiplot
GP
echo "soak: wrote $OUT/soak.png"

if grep -q '"passed": true' "$OUT/soak.json"; then exit 0; fi
if grep -q '"passed": false' "$OUT/soak.json"; then echo "soak: a check failed (see above)" >&2; exit 1; fi
echo "soak: the run was too short for the checks" >&2
exit 2
