#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>

#include "ret3d/io/kitti.h"
#include "support/parse_error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::size_t nonBlankLines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) n += line.find_first_not_of(" \t\r") != std::string::npos;
  return n;
}

std::vector<std::string> filesIn(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// The message must say where (file:line) and what (the field), as the header promises.
void expectParseError(const std::function<void()>& fn, const std::string& where, const std::string& field,
                      const std::string& problem) {
  const std::string msg = test::parseErrorMessage(fn);
  EXPECT_EQ(msg.rfind(where + ": field '" + field + "': ", 0), 0u) << msg;
  EXPECT_NE(msg.find(problem), std::string::npos) << msg;
}

kitti::Label sampleLabel() {
  kitti::Label l;
  l.type = "Car";
  l.truncated = 0.25;
  l.occluded = 2;
  l.alpha = -1.234567;
  l.bbox = {{387.63, 181.54, 423.81, 203.12}};
  l.h = 1.67;
  l.w = 1.87;
  l.l = 3.69;
  l.x = -16.53;
  l.y = 2.39;
  l.z = 58.49;
  l.rotation_y = 1.57;
  return l;
}

void expectSame(const kitti::Label& a, const kitti::Label& b, double tol) {
  EXPECT_EQ(a.type, b.type);
  EXPECT_NEAR(a.truncated, b.truncated, tol);
  EXPECT_EQ(a.occluded, b.occluded);
  EXPECT_NEAR(a.alpha, b.alpha, tol);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(a.bbox[k], b.bbox[k], tol);
  EXPECT_NEAR(a.h, b.h, tol);
  EXPECT_NEAR(a.w, b.w, tol);
  EXPECT_NEAR(a.l, b.l, tol);
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
  EXPECT_NEAR(a.rotation_y, b.rotation_y, tol);
  ASSERT_EQ(a.score.has_value(), b.score.has_value());
  if (a.score) {
    EXPECT_NEAR(*a.score, *b.score, tol);
  }
}

TEST(Labels, ReadsTheObjectLayout) {
  TempDir tmp;
  writeText(tmp / "000001.txt",
            "Truck 0.00 0 -1.57 599.41 156.40 629.75 189.25 2.85 2.63 12.34 0.47 1.49 69.44 -1.56\n"
            "\n"
            "DontCare -1 -1 -10 503.89 169.71 590.61 190.13 -1 -1 -1 -1000 -1000 -1000 -10\r\n"
            "Car 0.5 1 0.1 1 2 3 4 1.5 1.6 3.9 1 2 30 0.2 0.875\n");
  const auto labels = kitti::readObjectLabels(tmp / "000001.txt");
  ASSERT_EQ(labels.size(), 3u);
  EXPECT_EQ(labels[0].type, "Truck");
  EXPECT_DOUBLE_EQ(labels[0].l, 12.34);
  EXPECT_DOUBLE_EQ(labels[0].z, 69.44);
  EXPECT_DOUBLE_EQ(labels[0].rotation_y, -1.56);
  EXPECT_EQ(labels[0].frame, -1);
  EXPECT_FALSE(labels[0].score);
  EXPECT_EQ(labels[1].type, "DontCare");
  EXPECT_EQ(labels[1].occluded, -1);
  EXPECT_DOUBLE_EQ(labels[1].bbox[2], 590.61);
  ASSERT_TRUE(labels[2].score);
  EXPECT_DOUBLE_EQ(*labels[2].score, 0.875);
  EXPECT_DOUBLE_EQ(labels[2].truncated, 0.5);
}

TEST(Labels, ReadsTheTrackingLayout) {
  TempDir tmp;
  writeText(tmp / "0001.txt",
            "0 -1 DontCare -1 -1 -10.000000 356.400000 195.810000 374.100000 216.650000 -1000.000000 -1000.000000 "
            "-1000.000000 -10.000000 -1.000000 -1.000000 -1.000000\n"
            "3 7 Cyclist 2 1 -0.5 10 20 30 40 1.7 0.6 1.8 4 1.6 20 -0.4 0.5\n");
  const auto labels = kitti::readTrackingLabels(tmp / "0001.txt");
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].frame, 0);
  EXPECT_EQ(labels[0].track_id, -1);
  EXPECT_EQ(labels[0].type, "DontCare");
  EXPECT_EQ(labels[1].frame, 3);
  EXPECT_EQ(labels[1].track_id, 7);
  EXPECT_EQ(labels[1].type, "Cyclist");
  EXPECT_DOUBLE_EQ(labels[1].truncated, 2);
  EXPECT_EQ(labels[1].occluded, 1);
  EXPECT_DOUBLE_EQ(labels[1].rotation_y, -0.4);
  ASSERT_TRUE(labels[1].score);
  EXPECT_DOUBLE_EQ(*labels[1].score, 0.5);
}

TEST(Labels, ObjectWriteReadRoundTrip) {
  TempDir tmp;
  kitti::Label a = sampleLabel();
  kitti::Label b = sampleLabel();
  b.type = "Pedestrian";
  b.x = 1.0 / 3.0;  // needs more than KITTI's 2 decimals
  b.rotation_y = -3.14159;
  b.score = 0.123456;
  kitti::writeObjectLabels(tmp / "l.txt", {a, b});
  const auto back = kitti::readObjectLabels(tmp / "l.txt");
  ASSERT_EQ(back.size(), 2u);
  expectSame(back[0], a, 1e-6);
  expectSame(back[1], b, 1e-6);
  // 15 fields without a score, 16 with one: what the KITTI devkit reads.
  const std::string line_a = kitti::formatObjectLabel(a), line_b = kitti::formatObjectLabel(b);
  EXPECT_EQ(line_a.find('\n'), std::string::npos);
  EXPECT_EQ(std::count(line_a.begin(), line_a.end(), ' '), 14) << line_a;
  EXPECT_EQ(std::count(line_b.begin(), line_b.end(), ' '), 15) << line_b;
  EXPECT_EQ(line_a.rfind("Car 0.250000 2 -1.234567 387.630000 ", 0), 0u) << line_a;
}

TEST(Labels, TrackingWriteReadRoundTripWritesIntegerTruncation) {
  TempDir tmp;
  kitti::Label a = sampleLabel();
  a.frame = 12;
  a.track_id = 3;
  a.truncated = 1;
  kitti::Label b = a;
  b.frame = 13;
  b.track_id = -1;
  b.type = "DontCare";
  b.score = 0.9;
  kitti::writeTrackingLabels(tmp / "t.txt", {a, b});
  const std::string line = kitti::formatTrackingLabel(a);
  EXPECT_EQ(line.rfind("12 3 Car 1 2 ", 0), 0u) << line;  // frame, id, type, integer truncation, occlusion
  const auto back = kitti::readTrackingLabels(tmp / "t.txt");
  ASSERT_EQ(back.size(), 2u);
  expectSame(back[0], a, 1e-6);
  expectSame(back[1], b, 1e-6);
  EXPECT_EQ(back[0].frame, 12);
  EXPECT_EQ(back[0].track_id, 3);
  EXPECT_EQ(back[1].track_id, -1);
  a.frame = -1;  // e.g. straight from boxToLabel
  EXPECT_THROW(kitti::formatTrackingLabel(a), std::invalid_argument);
}

TEST(Labels, MalformedLinesNameFileLineAndField) {
  TempDir tmp;
  const std::string good = "Car 0.00 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 58.49 1.57";
  const std::string path = tmp / "bad.txt";

  writeText(path, good + "\n\nCar 0.00 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39\n");
  expectParseError([&] { kitti::readObjectLabels(path); }, path + ":3", "z", "the line has 13 fields");

  writeText(path, good + "\n" + good + " 0.9 17\n");
  expectParseError([&] { kitti::readObjectLabels(path); }, path + ":2", "score", "extra field");

  writeText(path, "Car 0.00 0 1.85 387.63 181.54 423.81 203.12 1.67 wide 3.69 -16.53 2.39 58.49 1.57\n");
  expectParseError([&] { kitti::readObjectLabels(path); }, path + ":1", "width", "'wide' is not a number");

  writeText(path, "Car 0.00 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 nan 1.57\n");
  expectParseError([&] { kitti::readObjectLabels(path); }, path + ":1", "z", "not a finite number");

  writeText(path, "Car 0.00 0.5 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 58.49 1.57\n");
  expectParseError([&] { kitti::readObjectLabels(path); }, path + ":1", "occluded", "not an integer");

  // The tracking layout: object lines lack frame and track id; truncation must be an integer level.
  writeText(path, good + "\n");
  expectParseError([&] { kitti::readTrackingLabels(path); }, path + ":1", "z", "the line has 15 fields");
  writeText(path, "0 1 Car 0.3 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 58.49 1.57\n");
  expectParseError([&] { kitti::readTrackingLabels(path); }, path + ":1", "truncated", "not an integer");
  writeText(path, "x 1 Car 0 0 1.85 387.63 181.54 423.81 203.12 1.67 1.87 3.69 -16.53 2.39 58.49 1.57\n");
  expectParseError([&] { kitti::readTrackingLabels(path); }, path + ":1", "frame", "'x' is not a number");
}

TEST(Labels, EveryRealLabelFileParses) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  std::size_t files = 0, labels = 0;
  std::set<std::string> types;
  for (const auto& path : filesIn(*data + "/kitti_tracking/training/label_02")) {
    const auto ls = kitti::readTrackingLabels(path);
    EXPECT_EQ(ls.size(), nonBlankLines(path)) << path;
    int last_frame = 0;
    for (const auto& l : ls) {
      EXPECT_GE(l.frame, last_frame) << path;  // frames ascend
      last_frame = l.frame;
      EXPECT_EQ(l.type == "DontCare", l.track_id == -1) << path << " frame " << l.frame;
      types.insert(l.type);
    }
    ++files;
    labels += ls.size();
  }
  EXPECT_EQ(files, 20u);
  EXPECT_EQ(labels, 64212u);
  for (const char* t : {"Car", "Van", "Truck", "Pedestrian", "Person", "Cyclist", "Tram", "Misc", "DontCare"}) {
    EXPECT_EQ(types.count(t), 1u) << t;
  }
  std::size_t labelled_frames = 0;
  for (const auto& path : filesIn(*data + "/kitti_object/training/label_2")) {
    const auto ls = kitti::readObjectLabels(path);
    EXPECT_EQ(ls.size(), nonBlankLines(path)) << path;
    const std::string frame = fs::path(path).stem().string();
    const auto& known = test::kLabelledObjectFrames;
    labelled_frames += std::find(known.begin(), known.end(), frame) != known.end();
  }
  EXPECT_EQ(labelled_frames, test::kLabelledObjectFrames.size());
}

TEST(Labels, RealFileRewritesToTheSameLabels) {
  const auto data = test::sharedDataDir();
  if (!data) GTEST_SKIP() << test::kSharedDataMissing;
  TempDir tmp;
  const auto orig = kitti::readTrackingLabels(*data + "/kitti_tracking/training/label_02/0001.txt");
  kitti::writeTrackingLabels(tmp / "0001.txt", orig);
  const auto back = kitti::readTrackingLabels(tmp / "0001.txt");
  ASSERT_EQ(back.size(), orig.size());
  for (std::size_t i = 0; i < orig.size(); ++i) {
    EXPECT_EQ(back[i].frame, orig[i].frame);
    EXPECT_EQ(back[i].track_id, orig[i].track_id);
    expectSame(back[i], orig[i], 1e-6);
  }
}

}  // namespace
}  // namespace ret3d
