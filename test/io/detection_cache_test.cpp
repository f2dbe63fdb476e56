#include "ret3d/io/detection_cache.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

io::SequenceDetections sample() {
  io::SequenceDetections d;
  Detections a;
  a.feature_dim = 3;
  Box b;
  b.x = 1.5, b.y = -2.25, b.z = -0.8, b.length = 4.1, b.width = 1.7, b.height = 1.5, b.yaw = 0.3, b.vx = 5, b.vy = -1;
  b.score = 0.75f, b.label = ObjectClass::Car, b.track_id = 7, b.num_points = 120;
  a.boxes.push_back(b);
  b.label = ObjectClass::Cyclist, b.x = 10, b.score = 0.5f;
  a.boxes.push_back(b);
  a.features = {1, 2, 3, 4, 5, 6};
  d["0000"][0] = a;
  d["0000"][1] = Detections{};
  d["0003"][12] = a;
  return d;
}

TEST(DetectionCache, RoundTripsBoxesAndFeatures) {
  test::TempDir dir;
  const std::string path = dir.path() + "/d.cache";
  const auto in = sample();
  io::writeDetectionCache(path, "model A", in);
  io::SequenceDetections out;
  ASSERT_TRUE(io::readDetectionCache(path, "model A", &out));
  ASSERT_EQ(out.size(), 2u);
  ASSERT_EQ(out["0000"].size(), 2u);
  EXPECT_TRUE(out["0000"][1].empty());
  const Detections& a = out["0003"][12];
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.feature_dim, 3u);
  EXPECT_EQ(a.features, in.at("0003").at(12).features);
  const Box& b = a.boxes[0];
  EXPECT_DOUBLE_EQ(b.y, -2.25);
  EXPECT_DOUBLE_EQ(b.yaw, 0.3);
  EXPECT_DOUBLE_EQ(b.vx, 5);
  EXPECT_FLOAT_EQ(b.score, 0.75f);
  EXPECT_EQ(b.label, ObjectClass::Car);
  EXPECT_EQ(b.track_id, 7u);
  EXPECT_EQ(b.num_points, 120u);
  EXPECT_EQ(a.boxes[1].label, ObjectClass::Cyclist);
}

TEST(DetectionCache, AnotherKeyOrNoFileIsAMissNotAnError) {
  test::TempDir dir;
  const std::string path = dir.path() + "/d.cache";
  io::SequenceDetections out;
  EXPECT_FALSE(io::readDetectionCache(path, "model A", &out));
  io::writeDetectionCache(path, "model A", sample());
  EXPECT_FALSE(io::readDetectionCache(path, "model B", &out));
  EXPECT_TRUE(out.empty());
}

TEST(DetectionCache, TruncatedOrForeignFilesAreRefusedNamingTheFile) {
  test::TempDir dir;
  const std::string path = dir.path() + "/d.cache";
  io::writeDetectionCache(path, "k", sample());
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 5);
  io::SequenceDetections out;
  const std::string msg = test::errorMessage([&] { io::readDetectionCache(path, "k", &out); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  std::ofstream(path) << "hello, not a cache at all";
  EXPECT_THROW(io::readDetectionCache(path, "k", &out), std::runtime_error);
}

// Found by fuzzing (test/fuzz/regressions/kitti_io): a damaged box count or feature size made the reader allocate
// gigabytes (or throw std::bad_alloc) for a file of a few hundred bytes.
TEST(DetectionCache, CountsBeyondTheFileAreRefusedBeforeAllocating) {
  test::TempDir dir;
  const std::string path = dir.path() + "/d.cache";
  io::writeDetectionCache(path, "k", sample());
  // The first entry's box count and feature size: after magic, version, key, entry count, sequence and frame.
  const std::streamoff count_at = 8 + 4 + (8 + 1) + 8 + (8 + 4) + 4;
  {
    std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(count_at);
    const std::uint64_t n = 1u << 20, dim = 1u << 16;
    f.write(reinterpret_cast<const char*>(&n), sizeof(n));
    f.write(reinterpret_cast<const char*>(&dim), sizeof(dim));
  }
  io::SequenceDetections out;
  const std::string msg = test::errorMessage([&] { io::readDetectionCache(path, "k", &out); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
}

}  // namespace
}  // namespace ret3d
