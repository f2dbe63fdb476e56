#include "ret3d/relation/radius_graph.h"

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

namespace ret3d {
namespace relation {
namespace {

std::set<std::pair<std::int64_t, std::int64_t>> edgeSet(const RadiusGraph& g) {
  std::set<std::pair<std::int64_t, std::int64_t>> s;
  for (std::size_t k = 0; k < g.numEdges(); ++k) s.insert({g.source[k], g.target[k]});
  return s;
}

TEST(RadiusGraph, HoldsExactlyThePairsWithinRadiusOnRandomLayouts) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 300);
    const double extent = 5.0 + (rng() % 60);  // from crowded to sparse
    const double radius = std::vector<double>{0.5, 1.0, 2.0, 4.0, 7.5}[rng() % 5];
    std::uniform_real_distribution<double> u(-extent, extent);
    std::vector<Eigen::Vector2d> c(n);
    for (auto& p : c) p = {u(rng), u(rng)};
    if (n > 3) c[1] = c[0] + Eigen::Vector2d(radius, 0);  // exactly at the radius: inclusive
    const RadiusGraph g = buildRadiusGraph(c, radius);
    std::set<std::pair<std::int64_t, std::int64_t>> brute;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if ((c[i] - c[j]).norm() <= radius * (1 + 1e-12)) brute.insert({j, i});
    EXPECT_EQ(edgeSet(g), brute) << "trial " << trial << " n " << n << " r " << radius;
    EXPECT_EQ(g.numEdges(), brute.size()) << "no duplicate edges";
    ASSERT_EQ(g.numNodes(), static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      for (auto k = g.offset[i]; k < g.offset[i + 1]; ++k) EXPECT_EQ(g.target[k], i) << "edges grouped by target";
    }
  }
}

TEST(RadiusGraph, NoEdgeVariantAndEmptyAndNonFinite) {
  std::vector<Eigen::Vector2d> c = {{0, 0}, {0.5, 0}, {1, 0}};
  const RadiusGraph none = buildRadiusGraph(c, 2.0, /*with_edges=*/false);
  EXPECT_EQ(edgeSet(none), (std::set<std::pair<std::int64_t, std::int64_t>>{{0, 0}, {1, 1}, {2, 2}}));
  EXPECT_EQ(buildRadiusGraph(c, 0.0).numEdges(), 3u);
  const RadiusGraph empty = buildRadiusGraph({}, 2.0);
  EXPECT_EQ(empty.numNodes(), 0u);
  EXPECT_EQ(empty.numEdges(), 0u);
  c[1] = {std::numeric_limits<double>::quiet_NaN(), 0};
  const RadiusGraph g = buildRadiusGraph(c, 2.0);
  EXPECT_EQ(edgeSet(g), (std::set<std::pair<std::int64_t, std::int64_t>>{{0, 0}, {2, 0}, {0, 2}, {2, 2}, {1, 1}}));
}

TEST(RadiusGraph, ScalesToThousandsOfObjects) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-80, 80);
  std::vector<Eigen::Vector2d> c(5000);
  for (auto& p : c) p = {u(rng), u(rng)};
  const RadiusGraph g = buildRadiusGraph(c, 2.0);
  EXPECT_EQ(g.numNodes(), 5000u);
  EXPECT_GE(g.numEdges(), 5000u);
  EXPECT_LT(g.numEdges(), 5000u * 10);  // sparse: about 1 + n * pi r^2 / area neighbours each
}

}  // namespace
}  // namespace relation
}  // namespace ret3d
