# Source this file (from bash) to use the built package: `source scripts/env.sh`.
# Debian's ROS tools need the system python first on PATH and /usr/share on ROS_PACKAGE_PATH.
_ret3d_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export PATH=/usr/bin:/bin:$PATH
source "$_ret3d_root/build/devel/setup.bash"
# third_party/vision_msgs when this build made it (the system has no vision_msgs): rospack does not look inside the
# package's own folder.
if [[ -d "$_ret3d_root/build/devel/share/vision_msgs" ]]; then
  export ROS_PACKAGE_PATH="$_ret3d_root:$_ret3d_root/third_party/vision_msgs:/usr/share"
else
  export ROS_PACKAGE_PATH="$_ret3d_root:/usr/share"
fi
unset _ret3d_root
# libtorch's OpenMP threads sleep rather than spin while they wait: on 2 busy cores spinning threads made the
# detector network and InterRM 10-30x slower (docs/RESULTS.md). The launch files set the same for the nodelets.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
