#!/usr/bin/env bash
# Builds the package with AddressSanitizer + UndefinedBehaviorSanitizer (+ LeakSanitizer) into build-asan/ and runs
# the whole gtest + rostest suite through ctest there. Only the package's own code is instrumented
# (-DRET3D_SANITIZE); libtorch, ROS, Embree and python are not. Any sanitizer report fails the run: the reports
# are written to build-asan/sanitizer/ and printed at the end.
# Usage: scripts/sanitize.sh [--no-build] [ctest arguments, e.g. -R ret3d_io_tests]
#   --no-build: run the tests of the existing build-asan/ as they are (e.g. again after a fix built by hand)
# Environment: RET3D_SANITIZE_JOBS (build jobs, default 2); RET3D_LSAN_EXTRA (more LSAN_OPTIONS, e.g.
# verbosity=1:log_threads=1); RET3D_SANITIZE (-fsanitize= list, default
# address,undefined,float-cast-overflow: GCC leaves the last out of `undefined`, and a NaN or huge coordinate cast
# to a grid index is exactly the UB a LiDAR scan can bring).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD="$ROOT/build-asan"
SANITIZE=${RET3D_SANITIZE:-address,undefined,float-cast-overflow}
# Debian's ROS 1 tools need the system python (a pyenv python3 lacks the ROS modules).
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH

BUILD_IT=1
if [[ "${1:-}" == "--no-build" ]]; then BUILD_IT=0; shift; fi

# The Debian packages (scripts/setup.sh installs them; this only checks).
scripts/setup.sh --no-build

# The normal build's configuration (scripts/setup.sh) plus the sanitizers; -O1 -g (as the sanitizers' manuals
# advise) keeps the reports' stacks readable, the compile time bearable and the training tests fast enough.
if ((BUILD_IT)); then
  echo "ret3d sanitize: configuring and building into build-asan/ (-fsanitize=$SANITIZE) ..."
  mkdir -p "$BUILD"
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g -DNDEBUG" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=ON -DRET3D_SANITIZE="$SANITIZE" \
    >"$BUILD/build.log" 2>&1 || { cat "$BUILD/build.log"; exit 1; }
  if ! nice -n 5 cmake --build "$BUILD" -j"${RET3D_SANITIZE_JOBS:-2}" --target all tests >>"$BUILD/build.log" 2>&1; then
    grep -E "error|Error" -A3 "$BUILD/build.log" | head -60 >&2
    echo "ret3d sanitize: build failed; the full log is in build-asan/build.log" >&2
    exit 1
  fi
fi

# ROS's setup scripts read unset variables: source them without nounset.
set +u
source "$BUILD/devel/setup.bash"
set -u
export ROS_PACKAGE_PATH="$ROOT:/usr/share"
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
export ROS_HOME="$BUILD/ros_home"
export ROS_LOG_DIR="$ROS_HOME/log"
mkdir -p "$ROS_LOG_DIR"

# ASan / LSan reports of every process (the tests, the `ret3d` commands they run, the nodelet manager roslaunch
# starts) go to files here, so a report from a child process whose output a test swallows is still seen.
REPORTS="$BUILD/sanitizer"
rm -rf "$REPORTS"
mkdir -p "$REPORTS"
SUPP="$ROOT/scripts/sanitizers"
# intercept_tls_get_addr=0: LeakSanitizer's own tracking of dynamic TLS blocks (__tls_get_addr) misreads glibc's
# layout now and then (google/sanitizers#1322: a header-size test on the block's address passes by chance) and hands
# the tracer a garbage range; it then dies at exit with "Tracer caught signal 11" (here: the nodelet manager of the
# replay_accuracy rostest, "DTLS 13 at 0x0016000024d6-0x003a000035d8", with LSAN_OPTIONS=verbosity=1:log_threads=1).
# Without the interception the thread-local blocks of dlopen'd libraries are not leak roots: a leak report that only
# such a block could explain would be a false one.
# detect_odr_violation=1: the tests that load libret3d_nodelets.so in-process also link the same static layers, so
# each global exists twice by design; level 1 still reports two definitions of different sizes (a real ODR bug).
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:detect_stack_use_after_return=1:\
check_initialization_order=1:strict_init_order=1:detect_odr_violation=1:intercept_tls_get_addr=0:print_suppressions=0:\
suppressions=$SUPP/asan.supp:log_path=$REPORTS/asan"
export LSAN_OPTIONS="suppressions=$SUPP/lsan.supp:print_suppressions=0${RET3D_LSAN_EXTRA:+:$RET3D_LSAN_EXTRA}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$SUPP/ubsan.supp"
# The nodelet manager (/usr/lib/nodelet/nodelet, not instrumented) loads the instrumented libret3d_nodelets.so: the
# ASan runtime must be loaded first, so launch/ret3d.launch starts it with this prefix (empty otherwise).
export RET3D_MANAGER_PREFIX="env LD_PRELOAD=$(g++ -print-file-name=libasan.so)"

echo "ret3d sanitize: running the suite (ASAN_OPTIONS=$ASAN_OPTIONS)"
cd "$BUILD"
start=$(date +%s)
set +e
ctest --output-on-failure --timeout 3000 "$@" 2>&1 | tee "$REPORTS/ctest.log"
rc=${PIPESTATUS[0]}
set -e
echo "ret3d sanitize: ctest took $(( $(date +%s) - start )) s"
# GCC's UBSan, linked together with ASan, ignores log_path and reports on stderr: those are in the ctest output.
ubsan=$(grep -c "runtime error:" "$REPORTS/ctest.log" || true)
if compgen -G "$REPORTS/[al]san*" >/dev/null || ((ubsan)); then
  echo "ret3d sanitize: sanitizer reports ($ubsan UBSan in build-asan/sanitizer/ctest.log):" >&2
  grep -h "runtime error:" "$REPORTS/ctest.log" | sort | uniq -c >&2 || true
  for f in "$REPORTS"/[al]san*; do [[ -e "$f" ]] && { echo "== $f" >&2; head -80 "$f" >&2; }; done
  rc=1
else
  echo "ret3d sanitize: no sanitizer reports"
fi
exit $rc
