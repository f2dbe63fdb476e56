#!/usr/bin/env bash
# Builds the libFuzzer targets of test/fuzz (clang, ASan + UBSan, into build/fuzz) and runs each for SECONDS on its
# corpus: the committed seeds (test/fuzz/corpus/<target>), the repository's config files and models for the config
# and model targets, and whatever earlier runs added (out/fuzz/<target>/corpus). Before fuzzing, every committed
# regression input (test/fuzz/regressions/<target>) is replayed once. Prints executions and findings per target;
# findings go to out/fuzz/<target>/artifacts. Exits 1 on any finding (crash, leak, sanitizer report, out-of-memory,
# timeout), 77 when clang or libFuzzer is missing (ctest reports the test as skipped).
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET (600)] [TARGET...]
#   targets: pointcloud2 kitti_io config model_file bag_check (default: all, one after the other)
# Environment: FUZZ_JOBS build parallelism (2); FUZZ_SKIP_BUILD=1 uses the targets already in build/fuzz (to run two
# instances side by side without two builds in one folder); FUZZ_OUT the working folder (out/fuzz); FUZZ_SEED a fixed
# libFuzzer seed; FUZZ_FRESH=1 starts from the committed seeds only (FUZZ_OUT emptied first). ctest's fuzz_smoke uses
# all three (seed 1, a fresh corpus in the build folder): the same inputs on every machine of about this speed, so CI
# fails on what a developer's run of the same commit fails on. The long runs (defaults) explore with fresh seeds.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
export PATH=/usr/bin:/bin:$PATH

SECONDS_PER_TARGET=${1:-600}
shift || true
ALL_TARGETS=(pointcloud2 kitti_io config model_file bag_check)
TARGETS=("$@")
((${#TARGETS[@]})) || TARGETS=("${ALL_TARGETS[@]}")
for t in "${TARGETS[@]}"; do
  [[ " ${ALL_TARGETS[*]} " == *" $t "* ]] || { echo "fuzz: unknown target '$t' (known: ${ALL_TARGETS[*]})" >&2; exit 2; }
done

CLANG=${CLANG:-/usr/bin/clang++}
if [[ ! -x "$CLANG" ]] || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "fuzz: skipped: clang++ ($CLANG) or libFuzzer (libclang_rt.fuzzer, Debian package clang) is not installed"
  exit 77
fi

BUILD="$ROOT/build/fuzz"
OUT="${FUZZ_OUT:-$ROOT/out/fuzz}"
[[ "${FUZZ_FRESH:-0}" != 1 ]] || rm -rf "$OUT"
start=$(date +%s)
if [[ "${FUZZ_SKIP_BUILD:-0}" != 1 ]]; then
  echo "fuzz: building ${TARGETS[*]} into build/fuzz ..."
  mkdir -p "$BUILD"
  if ! { cmake -S "$ROOT/test/fuzz" -B "$BUILD" -DCMAKE_CXX_COMPILER="$CLANG" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
           -DPYTHON_EXECUTABLE=/usr/bin/python3 &&
         nice -n 5 cmake --build "$BUILD" -j"${FUZZ_JOBS:-2}" --target "${TARGETS[@]/%/_fuzz}"; } >"$BUILD/build.log" 2>&1; then
    grep -E "error|Error" -A3 "$BUILD/build.log" | head -40 >&2
    echo "fuzz: build failed; the log is build/fuzz/build.log" >&2
    exit 1
  fi
  echo "fuzz: built in $(($(date +%s) - start)) s"
fi

# A run's options: the limits make huge allocations and hangs findings, not slowness.
export OMP_NUM_THREADS=1
FUZZ_OPTS=(-rss_limit_mb=2560 -malloc_limit_mb=1024 -timeout=30 -print_final_stats=1)
[[ -z "${FUZZ_SEED:-}" ]] || FUZZ_OPTS+=(-seed="$FUZZ_SEED")

# Seeds that are not committed because the repository already holds them: the selector byte, then the file.
add_seeds() {
  local target=$1 dir=$2 sel f
  case $target in
    config)
      for f in config/detector/*.yaml; do { printf 0; cat "$f"; } >"$dir/repo_$(basename "$f")"; done
      for f in config/tracker*.yaml; do { printf 1; cat "$f"; } >"$dir/repo_$(basename "$f")"; done
      for f in config/relation/intra*.yaml; do { printf 2; cat "$f"; } >"$dir/repo_$(basename "$f")"; done
      for f in config/relation/inter*.yaml; do { printf 3; cat "$f"; } >"$dir/repo_$(basename "$f")"; done
      for f in config/sim/*.yaml; do { printf 4; cat "$f"; } >"$dir/repo_sim_$(basename "$f")"; done
      for f in config/sensors/*.yaml; do { printf 5; cat "$f"; } >"$dir/repo_sensor_$(basename "$f")"; done
      ;;
    model_file)
      # The repository models' metadata (and the detector file whole), written by the target itself.
      RET3D_FUZZ_WRITE_SEEDS="$dir" "$BUILD/model_file_fuzz" -runs=0 -artifact_prefix="$dir/../seeding-" "$dir" >/dev/null 2>&1
      ;;
  esac
}

status=0
summary=()
for t in "${TARGETS[@]}"; do
  bin="$BUILD/${t}_fuzz"
  work="$OUT/$t"
  mkdir -p "$work/corpus" "$work/artifacts"
  regressions=("$ROOT/test/fuzz/regressions/$t"/*)
  replay="no regressions"
  if [[ -e "${regressions[0]}" ]]; then
    if "$bin" "${FUZZ_OPTS[@]}" "${regressions[@]}" >"$work/replay.log" 2>&1; then
      replay="${#regressions[@]} regressions pass"
    else
      replay="REGRESSION FAILS ($work/replay.log)"
      status=1
    fi
  fi
  cp "$ROOT/test/fuzz/corpus/$t"/* "$work/corpus/"
  add_seeds "$t" "$work/corpus"
  before=$(ls "$work/artifacts" | wc -l)
  echo "fuzz: $t for $SECONDS_PER_TARGET s ($replay) ..."
  # libFuzzer exits non-zero on its first finding; the artifact count below is what is reported.
  (cd "$work" && nice -n 10 "$bin" "${FUZZ_OPTS[@]}" -max_total_time="$SECONDS_PER_TARGET" -artifact_prefix=artifacts/ \
     corpus >"$work/fuzz.log" 2>&1) || true
  execs=$(grep -o "stat::number_of_executed_units: [0-9]*" "$work/fuzz.log" | grep -o "[0-9]*$" || echo "?")
  findings=$(($(ls "$work/artifacts" | wc -l) - before))
  kinds=$(grep -o "SUMMARY: [A-Za-z]*: [a-z -]*\|ret3d fuzz finding: .*" "$work/fuzz.log" | head -3 | tr '\n' ';' || true)
  line="$t: $execs executions, $(ls "$work/corpus" | wc -l) corpus inputs, $findings findings; $replay"
  if ((findings > 0)) || ! grep -q "stat::number_of_executed_units" "$work/fuzz.log"; then
    line+=" -- ${kinds:-see $work/fuzz.log}"
    status=1
  fi
  summary+=("$line")
  echo "fuzz: $line"
done
echo "fuzz: summary ($SECONDS_PER_TARGET s per target):"
printf '  %s\n' "${summary[@]}"
exit $status
