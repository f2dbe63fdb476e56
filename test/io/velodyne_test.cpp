#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "ret3d/io/kitti.h"
#include "support/error_message.h"
#include "support/parse_error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

using test::TempDir;

void writeRaw(const std::string& path, const std::vector<float>& values) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(float)));
}

TEST(Velodyne, WriteReadRoundTripIsExact) {
  TempDir tmp;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-80.0f, 80.0f), refl(0.0f, 1.0f);
  PointCloud cloud;
  for (int i = 0; i < 5000; ++i) cloud.points.push_back({pos(rng), pos(rng), pos(rng) * 0.05f, refl(rng)});
  const std::string path = tmp / "000000.bin";
  kitti::writeVelodyne(path, cloud);
  EXPECT_EQ(std::filesystem::file_size(path), 16u * 5000u);
  const PointCloud back = kitti::readVelodyne(path);
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_EQ(back.points[i].x, cloud.points[i].x);
    EXPECT_EQ(back.points[i].y, cloud.points[i].y);
    EXPECT_EQ(back.points[i].z, cloud.points[i].z);
    EXPECT_EQ(back.points[i].intensity, cloud.points[i].intensity);
  }
}

TEST(Velodyne, EmptyScanRoundTrips) {
  TempDir tmp;
  kitti::writeVelodyne(tmp / "e.bin", PointCloud{});
  EXPECT_TRUE(kitti::readVelodyne(tmp / "e.bin").empty());
}

TEST(Velodyne, SizeNotMultipleOf16IsAnErrorNamingTheFile) {
  TempDir tmp;
  const std::string path = tmp / "broken.bin";
  writeRaw(path, {1, 2, 3, 0.5f, 4, 5});  // 24 bytes: one and a half points
  const std::string msg = test::parseErrorMessage([&] { kitti::readVelodyne(path); });
  EXPECT_EQ(msg.rfind(path + ": size 24 bytes is not a multiple of 16", 0), 0u) << msg;
}

TEST(Velodyne, MissingFileThrowsNamingIt) {
  TempDir tmp;
  const std::string msg = test::errorMessage([&] { kitti::readVelodyne(tmp / "absent.bin"); });
  EXPECT_NE(msg.find("absent.bin"), std::string::npos) << msg;
}

TEST(Velodyne, NonFinitePointsDroppedAndReflectanceSanitised) {
  TempDir tmp;
  const float nan = std::nanf("");
  const float inf = INFINITY;
  writeRaw(tmp / "s.bin", {1, 2, 3, 0.25f,      // kept as is
                           nan, 0, 0, 0.5f,     // dropped
                           0, inf, 0, 0.5f,     // dropped
                           4, 5, 6, nan,        // kept, reflectance 0
                           7, 8, 9, -0.5f,      // kept, clamped to 0
                           1, 1, 1, 1.0f});     // kept
  const PointCloud c = kitti::readVelodyne(tmp / "s.bin");
  ASSERT_EQ(c.size(), 4u);
  EXPECT_FLOAT_EQ(c.points[0].intensity, 0.25f);
  EXPECT_FLOAT_EQ(c.points[1].x, 4.0f);
  EXPECT_FLOAT_EQ(c.points[1].intensity, 0.0f);
  EXPECT_FLOAT_EQ(c.points[2].intensity, 0.0f);
  EXPECT_FLOAT_EQ(c.points[3].intensity, 1.0f);
}

TEST(Velodyne, ByteScaledReflectanceIsNormalised) {
  TempDir tmp;
  writeRaw(tmp / "b.bin", {1, 0, 0, 255.0f, 2, 0, 0, 51.0f, 3, 0, 0, 0.0f});
  const PointCloud c = kitti::readVelodyne(tmp / "b.bin");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_FLOAT_EQ(c.points[0].intensity, 1.0f);
  EXPECT_FLOAT_EQ(c.points[1].intensity, 0.2f);
  EXPECT_FLOAT_EQ(c.points[2].intensity, 0.0f);
}

TEST(Velodyne, RealScansReadWithReflectanceInUnitRange) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  const kitti::ObjectDataset ds(*data + "/kitti_object");
  ASSERT_GE(ds.frames().size(), test::kLabelledObjectFrames.size());
  for (const auto& f : ds.frames()) {
    const std::string path = ds.velodynePath(f);
    const PointCloud c = kitti::readVelodyne(path);
    EXPECT_EQ(c.size() * 16, std::filesystem::file_size(path)) << path;  // KITTI scans are all finite
    EXPECT_GT(c.size(), 10000u) << path;
    float max_i = 0, max_r = 0;
    for (const Point& p : c.points) {
      ASSERT_GE(p.intensity, 0.0f);
      ASSERT_LE(p.intensity, 1.0f);
      max_i = std::max(max_i, p.intensity);
      max_r = std::max(max_r, std::hypot(p.x, p.y));
    }
    EXPECT_GT(max_i, 0.5f) << path;   // real reflectance spans the range
    EXPECT_GT(max_r, 40.0f) << path;  // an HDL-64E sees far
  }
}

}  // namespace
}  // namespace ret3d
