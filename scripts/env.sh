# Source this file (from bash) to use the built package: `source scripts/env.sh`.
# Debian's ROS tools need the system python first on PATH and /usr/share on ROS_PACKAGE_PATH.
_ret3d_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export PATH=/usr/bin:/bin:$PATH
source "$_ret3d_root/build/devel/setup.bash"
export ROS_PACKAGE_PATH="$_ret3d_root:/usr/share"
unset _ret3d_root
