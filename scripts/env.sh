# Source this file (from bash) to use the built package: `source scripts/env.sh`.
# Debian's ROS tools need the system python first on PATH and /usr/share on ROS_PACKAGE_PATH.
_ret3d_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export PATH=/usr/bin:/bin:$PATH
source "$_ret3d_root/build/devel/setup.bash"
export ROS_PACKAGE_PATH="$_ret3d_root:/usr/share"
unset _ret3d_root
# libtorch's OpenMP threads sleep rather than spin while they wait: on 2 busy cores spinning threads made the
# detector network and InterRM 10-30x slower (docs/RESULTS.md). The launch files set the same for the nodelets.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
