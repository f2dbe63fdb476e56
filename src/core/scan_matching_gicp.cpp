// ScanMatcher::Gicp: PCL's generalized ICP (Segal, Haehnel, Thrun 2009) on the points the ICP matches
// (scan_matching_points.h), started from the same ground-plane guess; its 6-DoF result is projected on the ground
// plane, as the ICP estimates it.
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "scan_matching_points.h"

namespace ret3d {
namespace scan_matching {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const Points& points) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const Eigen::Vector3d& p : points)
    cloud->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())));
  return cloud;
}

}  // namespace

ScanMatch matchGicp(const PointCloud& source, const PointCloud& target, const Eigen::Isometry3d& initial,
                    const ScanMatchingOptions& o) {
  ScanMatch result;
  const Points src = downsample(source, o), dst = downsample(target, o);
  // GICP's covariances need k = 20 neighbours per point; fewer points say nothing.
  if (static_cast<int>(std::min(src.size(), dst.size())) < std::max(o.min_correspondences, 20)) return result;
  const auto src_pcl = toPcl(src), dst_pcl = toPcl(dst);
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  gicp.setInputSource(src_pcl);
  gicp.setInputTarget(dst_pcl);
  gicp.setMaxCorrespondenceDistance(o.gicp_distance);
  gicp.setMaximumIterations(o.gicp_iterations);
  gicp.setTransformationEpsilon(1e-8);
  pcl::PointCloud<pcl::PointXYZ> aligned;
  gicp.align(aligned, planarPart(initial).matrix().cast<float>());
  const Eigen::Matrix4d M = gicp.getFinalTransformation().cast<double>();
  if (!M.allFinite()) return result;
  Eigen::Isometry3d T;
  T.matrix() = M;
  result.source_to_target = planarPart(T);
  // Correspondences and their RMSE after the match, as the ICP reports them: source points within last_distance.
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(dst_pcl);
  std::vector<int> index(1);
  std::vector<float> d2(1);
  double sq = 0;
  for (const Eigen::Vector3d& p : src) {
    const Eigen::Vector3f q = (result.source_to_target * p).cast<float>();
    if (tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 1, index, d2) == 1 &&
        d2[0] <= o.last_distance * o.last_distance) {
      sq += d2[0];
      ++result.correspondences;
    }
  }
  result.rmse = result.correspondences ? std::sqrt(sq / result.correspondences) : 0;
  result.converged = gicp.hasConverged() && result.correspondences >= o.min_correspondences;
  return result;
}

}  // namespace scan_matching
}  // namespace ret3d
