#include "rigid.h"

#include <Eigen/SVD>

namespace ret3d {
namespace kitti {
namespace detail {

Eigen::Isometry3d nearestIsometry(const Eigen::Matrix4d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.topLeftCorner<3, 3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) *= -1;  // a reflection: flip the weakest axis
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = u * svd.matrixV().transpose();
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

}  // namespace detail
}  // namespace kitti
}  // namespace ret3d
