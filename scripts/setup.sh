#!/usr/bin/env bash
# Installs what ret3d needs from Debian's packages (idempotent), then configures and builds the package into build/.
# Usage: scripts/setup.sh [--no-build]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

# Debian's ROS 1 tools need the system python (a pyenv python3 lacks the ROS modules).
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH

PACKAGES=(
  # build tools and libraries
  build-essential cmake catkin libeigen3-dev libyaml-cpp-dev libgtest-dev libcli11-dev
  libtorch-dev libembree-dev
  # an optimised BLAS for libtorch's matrix products (1x1 convolutions, attention): Debian's libtorch links the
  # generic libblas.so.3, which is the slow reference BLAS unless this alternative is installed (3-4x faster network)
  libopenblas0-openmp
  # ROS 1 from Debian
  ros-core-dev libroscpp-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev libtf2-ros-dev libtf2-eigen-dev
  libpcl-ros-dev libpcl-dev librosbag-dev libroslz4-dev libbz2-dev librostest-dev python3-rostest python3-roslaunch
  python3-rosbag
  python3-rostopic python3-rosnode rosbash ros-message-generation ros-sensor-msgs ros-visualization-msgs
  python3-sensor-msgs python3-geometry-msgs python3-visualization-msgs python3-tf2-msgs
  libdiagnostic-updater-dev libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  # checks, plots, visual tests; clang with libFuzzer for the fuzz targets (scripts/fuzz.sh)
  catkin-lint gnuplot-nox imagemagick rviz xvfb clang libclang-rt-14-dev
  # model-building scripts (scripts/fit_score_calibration.py; calibration_config.py reads `base:` chains)
  python3-numpy python3-yaml
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "ret3d setup: these Debian packages are missing: ${missing[*]}" >&2
    echo "Install them as root, then run this script again:" >&2
    echo "  sudo apt-get update && sudo apt-get install -y --no-install-recommends ${missing[*]}" >&2
    exit 1
  fi
  echo "ret3d setup: installing ${#missing[@]} Debian packages (a few minutes the first time)..."
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [[ "${1:-}" == "--no-build" ]]; then exit 0; fi

# vision_msgs (objects/detections): the system's when `rospack find vision_msgs` finds one outside this folder (a ROS
# distribution's package); otherwise third_party/vision_msgs is built with the package (Debian ships none).
system_vision_msgs=$(ROS_PACKAGE_PATH="${ROS_PACKAGE_PATH:+$ROS_PACKAGE_PATH:}/usr/share" rospack find vision_msgs \
  2>/dev/null || true)
if [[ -n "$system_vision_msgs" && "$system_vision_msgs" != "$ROOT"/* ]]; then
  echo "ret3d setup: vision_msgs from the system ($system_vision_msgs)"
  bundled_vision_msgs=OFF
else
  echo "ret3d setup: no vision_msgs on the system: third_party/vision_msgs is built with the package"
  bundled_vision_msgs=ON
fi

echo "ret3d setup: configuring and building into build/ ..."
cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_ENABLE_TESTING=ON -DRET3D_BUNDLED_VISION_MSGS=$bundled_vision_msgs >"$ROOT/build.log" 2>&1 \
  || { cat "$ROOT/build.log"; exit 1; }
if ! cmake --build "$ROOT/build" -j"$(nproc)" --target all tests >>"$ROOT/build.log" 2>&1; then
  grep -E "error|Error" -A3 "$ROOT/build.log" | head -60 >&2
  echo "ret3d setup: build failed; the full log is in build.log" >&2
  exit 1
fi
mv "$ROOT/build.log" "$ROOT/build/build.log"
echo "ret3d setup: built. To use it in this shell:"
echo "  source scripts/env.sh     # sources build/devel/setup.bash and sets ROS_PACKAGE_PATH"
