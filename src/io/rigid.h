// Internal to src/io: KITTI's calibration matrices are printed with 7 digits and so are only nearly rotations.
#pragma once

#include <Eigen/Geometry>

namespace ret3d {
namespace kitti {
namespace detail {

// The rigid transform closest to an affine 4x4 matrix: the rotation nearest its 3x3 part (SVD, Frobenius norm), the
// same translation. Poses chained through it stay rigid.
Eigen::Isometry3d nearestIsometry(const Eigen::Matrix4d& m);

}  // namespace detail
}  // namespace kitti
}  // namespace ret3d
