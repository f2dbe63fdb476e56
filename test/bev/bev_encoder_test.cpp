#include "ret3d/bev/bev_encoder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "support/test_util.h"

namespace ret3d {
namespace {

BevEncoderOptions smallGrid(int threads = 2) {
  BevEncoderOptions o;
  o.geometry.x_min = -4;
  o.geometry.x_max = 4;
  o.geometry.y_min = -2;
  o.geometry.y_max = 2;
  o.geometry.z_min = -2;
  o.geometry.z_max = 2;
  o.geometry.resolution = 0.5;  // 16 x 8 cells
  o.threads = threads;
  return o;
}

PointCloud cloudOf(std::initializer_list<Point> pts) {
  PointCloud c;
  for (const auto& p : pts) c.push_back(p);
  return c;
}

TEST(BevGeometry, SizesAndTransformsRoundTrip) {
  BevGeometry g = smallGrid().geometry;
  EXPECT_EQ(g.width(), 16);
  EXPECT_EQ(g.height(), 8);
  int u, v;
  ASSERT_TRUE(g.cellOf(0.1, -1.9, 0.0, &u, &v));
  EXPECT_EQ(u, 8);
  EXPECT_EQ(v, 0);
  EXPECT_FALSE(g.cellOf(4.0, 0, 0, &u, &v));   // x_max is exclusive
  EXPECT_FALSE(g.cellOf(0, 0, 2.5, &u, &v));   // above z_max
  EXPECT_FALSE(g.cellOf(NAN, 0, 0, &u, &v));
  const Eigen::Vector2d c = g.gridToMetric(8 + 0.5, 0 + 0.5);
  EXPECT_DOUBLE_EQ(c.x(), 0.25);
  EXPECT_DOUBLE_EQ(c.y(), -1.75);
  const Eigen::Vector2d f = g.metricToFeature(1.3, 0.7, 4);
  const Eigen::Vector2d back = g.featureToMetric(f.x(), f.y(), 4);
  EXPECT_NEAR(back.x(), 1.3, 1e-12);
  EXPECT_NEAR(back.y(), 0.7, 1e-12);
  BevGeometry bad = g;
  bad.resolution = 0.3;  // 8 / 0.3 is not whole
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = g;
  bad.z_max = bad.z_min;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(BevEncoder, ExactHeightDensityIntensityOfOneCell) {
  BevEncoder enc(smallGrid());
  // Three points in cell (u=10, v=5): x in [1, 1.5), y in [0.5, 1).
  const PointCloud cur = cloudOf({{1.1f, 0.6f, -1.0f, 0.2f}, {1.4f, 0.9f, 1.0f, 0.7f}, {1.2f, 0.7f, 0.0f, 0.4f}});
  const BevImage img = enc.encode(cur);
  ASSERT_EQ(img.channels, 6);
  ASSERT_EQ(img.height, 8);
  ASSERT_EQ(img.width, 16);
  EXPECT_FLOAT_EQ(img.at(0, 5, 10), (1.0f - -2.0f) / 4.0f);                       // eq. (1): max z normalised
  EXPECT_FLOAT_EQ(img.at(1, 5, 10), static_cast<float>(std::log(4.0) / std::log(64.0)));  // eq. (2), N = 3
  EXPECT_FLOAT_EQ(img.at(2, 5, 10), 0.7f);                                        // eq. (3): max intensity
  // Every other cell and the whole previous sweep are empty.
  float other = 0;
  for (int c = 0; c < 6; ++c)
    for (int v = 0; v < 8; ++v)
      for (int u = 0; u < 16; ++u)
        if (!(c < 3 && v == 5 && u == 10)) other += std::abs(img.at(c, v, u));
  EXPECT_EQ(other, 0.0f);
}

TEST(BevEncoder, DensitySaturatesAt64AndOutOfRangePointsAreDropped) {
  BevEncoder enc(smallGrid());
  PointCloud cur;
  for (int i = 0; i < 100; ++i) cur.push_back({-3.9f, -1.9f, 0.5f, 2.0f});  // intensity clamped to 1
  cur.push_back({-3.9f, -1.9f, 2.5f, 0.0f});   // above z range: not counted
  cur.push_back({-3.9f, -1.9f, -2.1f, 0.0f});  // below z range
  cur.push_back({5.0f, 0.0f, 0.0f, 0.5f});     // outside x
  cur.push_back({NAN, 0.0f, 0.0f, 0.5f});
  const BevImage img = enc.encode(cur);
  EXPECT_FLOAT_EQ(img.at(1, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(img.at(0, 0, 0), 2.5f / 4.0f);
  EXPECT_FLOAT_EQ(img.at(2, 0, 0), 1.0f);
  double total = 0;
  for (float x : img.data) total += x;
  EXPECT_NEAR(total, 1.0 + 2.5 / 4.0 + 1.0, 1e-6);

  // Exactly 63 points: log(64) / log(64) = 1; 62 points stays below.
  PointCloud c63, c62;
  for (int i = 0; i < 63; ++i) c63.push_back({0.1f, 0.1f, 0.0f, 0.0f});
  for (int i = 0; i < 62; ++i) c62.push_back({0.1f, 0.1f, 0.0f, 0.0f});
  EXPECT_FLOAT_EQ(enc.encode(c63).at(1, 4, 8), 1.0f);
  EXPECT_LT(enc.encode(c62).at(1, 4, 8), 1.0f);
}

// A corrupt driver or bag can send finite coordinates far beyond any grid: they are dropped, not cast to an int they
// do not fit (UB that wrote outside the image on x86; caught by scripts/sanitize.sh).
TEST(BevEncoder, HugeFiniteCoordinatesAreDropped) {
  BevEncoder enc(smallGrid());
  const float big = 1e30f, top = std::numeric_limits<float>::max();
  const PointCloud cur = cloudOf({{big, 0.1f, 0.0f, 0.5f}, {0.1f, big, 0.0f, 0.5f}, {top, top, 0.0f, 0.5f},
                                  {-big, 0.1f, 0.0f, 0.5f}, {0.1f, 0.1f, 0.0f, 0.5f}});
  const BevImage img = enc.encode(cur);
  double total = 0;
  for (float x : img.data) total += x;
  EXPECT_FLOAT_EQ(img.at(1, 4, 8), static_cast<float>(std::log(2.0) / std::log(64.0)));  // only the near point
  EXPECT_NEAR(total, 0.5 + std::log(2.0) / std::log(64.0) + 0.5, 1e-6);
}

TEST(BevEncoder, PreviousSweepIsMovedIntoTheCurrentFrame) {
  BevEncoder enc(smallGrid());
  const PointCloud cur = cloudOf({{0.1f, 0.1f, 0.0f, 0.5f}});
  const PointCloud prev = cloudOf({{0.1f, 0.1f, -1.0f, 0.9f}, {0.2f, 0.2f, -1.5f, 0.3f}});
  // The ego moved 2 m forward and turned 90 degrees left: the previous frame's (0.1, 0.1) lies at
  // R(90) * (0.1, 0.1) + (2, 0) = (1.9, 0.1) in the current frame, i.e. cell u = 11, v = 4.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  const BevImage img = enc.encode(cur, &prev, T);
  EXPECT_FLOAT_EQ(img.at(0, 4, 8), 0.5f);  // current sweep untouched
  EXPECT_FLOAT_EQ(img.at(3, 4, 8), 0.0f);
  // (0.2, 0.2) -> (1.8, 0.2): the same cell (11, 4)? x 1.8 -> u 11, y 0.2 -> v 4.
  EXPECT_FLOAT_EQ(img.at(3, 4, 11), (-1.0f + 2.0f) / 4.0f);
  EXPECT_FLOAT_EQ(img.at(4, 4, 11), static_cast<float>(std::log(3.0) / std::log(64.0)));
  EXPECT_FLOAT_EQ(img.at(5, 4, 11), 0.9f);
  EXPECT_FLOAT_EQ(img.at(0, 4, 11), 0.0f);  // nothing of the previous sweep leaks into the current channels
  // A translation along z moves heights: +0.5 m lifts the previous maximum to -0.5.
  T.translation().z() = 0.5;
  EXPECT_FLOAT_EQ(enc.encode(cur, &prev, T).at(3, 4, 11), 1.5f / 4.0f);
}

// Two sweeps of 20,000 points each, uniform over x +-sx, y +-sy, z +-2.5 m (a fixed generator: same on every machine).
std::pair<PointCloud, PointCloud> randomSweeps(std::uint32_t seed, float sx, float sy) {
  PointCloud cur, prev;
  auto rnd = [&]() { seed = seed * 1664525u + 1013904223u; return (seed >> 8) / 16777216.0f; };
  for (PointCloud* c : {&cur, &prev})
    for (int i = 0; i < 20000; ++i) c->push_back({(rnd() * 2 - 1) * sx, (rnd() * 2 - 1) * sy, rnd() * 5 - 2.5f, rnd()});
  return {cur, prev};
}

TEST(BevEncoder, ThreadCountDoesNotChangeTheResult) {
  const auto [cur, prev] = randomSweeps(12345, 4.5f, 2.5f);
  const Eigen::Isometry3d T(Eigen::Translation3d(0.3, -0.2, 0.1));
  const BevImage a = BevEncoder(smallGrid(1)).encode(cur, &prev, T);
  const BevImage b = BevEncoder(smallGrid(2)).encode(cur, &prev, T);
  const BevImage c = BevEncoder(smallGrid(3)).encode(cur, &prev, T);
  EXPECT_EQ(a.data, b.data);
  EXPECT_EQ(a.data, c.data);
}

// The two-resolution detector encodes its near and far grids in one pass: each image is the one its encoder makes
// alone, whatever the thread count, with and without a previous sweep.
TEST(BevEncoder, SeveralGridsAtOnceGiveEachGridsOwnImage) {
  const auto [cur, prev] = randomSweeps(777, 10, 5);
  const Eigen::Isometry3d T(Eigen::Translation3d(0.3, -0.2, 0.1));
  for (int threads : {1, 2, 3}) {
    BevEncoderOptions near = smallGrid(threads), far = smallGrid(threads);
    far.geometry.x_min = -10, far.geometry.x_max = 10, far.geometry.y_min = -5, far.geometry.y_max = 5;
    far.geometry.z_min = -1.5;
    far.geometry.resolution = 1.25;  // 16 x 8 cells of a grid 2.5 times as large
    far.density_norm = 16;
    const BevEncoder a(near), b(far);
    for (const PointCloud* p : {static_cast<const PointCloud*>(nullptr), &prev}) {
      BevImage ia, ib;
      BevEncoder::encodeAll({{&a, &ia}, {&b, &ib}}, cur, p, T);
      EXPECT_EQ(ia.data, a.encode(cur, p, T).data) << threads;
      EXPECT_EQ(ib.data, b.encode(cur, p, T).data) << threads;
      EXPECT_EQ(ib.width, 16);
      EXPECT_NE(ia.data, ib.data);
    }
  }
}

// Real HDL-64E scans fill the grid; prints the encode time against the 5 ms target (printed, never asserted).
TEST(BevEncoder, LatencyOnRealScans) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  namespace fs = std::filesystem;
  std::vector<PointCloud> scans;
  for (int i = 0; i < 4; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.bin", i);
    const fs::path p = fs::path(*data) / "unlabeled_scans" / name;
    std::ifstream in(p, std::ios::binary);
    if (!in) continue;
    in.seekg(0, std::ios::end);
    const std::size_t n = static_cast<std::size_t>(in.tellg()) / sizeof(Point);
    in.seekg(0);
    PointCloud c;
    c.points.resize(n);
    in.read(reinterpret_cast<char*>(c.points.data()), n * sizeof(Point));
    scans.push_back(std::move(c));
  }
  if (scans.size() < 2) GTEST_SKIP() << "unlabeled_scans not found";
  BevEncoderOptions o;  // the default 360-degree grid
  BevEncoder enc(o);
  const Eigen::Isometry3d T(Eigen::Translation3d(1.0, 0.0, 0.0));
  BevImage img;
  std::vector<double> ms;
  for (int it = 0; it < 30; ++it) {
    const auto t0 = std::chrono::steady_clock::now();
    enc.encode(scans[(it + 1) % scans.size()], &scans[it % scans.size()], T, &img);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  const double median = ms[ms.size() / 2];
  std::printf("BEV encode (%zu points, two sweeps, %s, 2 threads): median %.2f ms, p90 %.2f ms\n",
              scans[0].size(), o.geometry.describe().c_str(), median, ms[ms.size() * 9 / 10]);
  // Non-empty cells: a real scan fills thousands of cells.
  std::size_t occupied = 0;
  for (int v = 0; v < img.height; ++v)
    for (int u = 0; u < img.width; ++u) occupied += img.at(1, v, u) > 0;
  EXPECT_GT(occupied, 5000u);
}

}  // namespace
}  // namespace ret3d
