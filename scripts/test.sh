#!/usr/bin/env bash
# Sets up and builds (scripts/setup.sh), then runs every test: the gtest suites and the rostest integration tests,
# all through ctest. Ends with ctest's summary line; exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
scripts/setup.sh
# ROS's setup scripts read unset variables: source them without nounset.
set +u
source scripts/env.sh
set -u
# Keep ROS logs and any roscore state of the tests out of the user's home.
export ROS_HOME="$ROOT/build/ros_home"
export ROS_LOG_DIR="$ROS_HOME/log"
mkdir -p "$ROS_LOG_DIR"
cd build
ctest --output-on-failure --timeout 1500 "$@"
