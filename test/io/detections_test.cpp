#include "ret3d/io/detections.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "support/parse_error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace io {
namespace {

void write(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path) << text;
}

TEST(Detections, ReadsPerClassCommaSeparatedLines) {
  test::TempDir dir;
  write(dir / "Car/0003.txt",
        "0,2,786.7492,180.1760,1241.0000,374.0000,12.2286,1.5206,1.6824,4.4501,2.9312,1.6089,6.4281,-1.5828,-2.0107\n"
        "\n"
        "4,2,1,2,3,4,0.5,1,2,3,4,5,6,0.1,0.2\n");
  write(dir / "Pedestrian/0003.txt", "4,1,10,20,30,40,0.9,1.7,0.6,0.8,1,1.6,12,0.3,0.4\n");
  const auto labels = readPerClassCsvDetections(dir / "Car/0003.txt");
  ASSERT_EQ(labels.size(), 2u);
  const kitti::Label& l = labels[0];
  EXPECT_EQ(l.frame, 0);
  EXPECT_EQ(l.type, "Car");
  EXPECT_DOUBLE_EQ(l.bbox[0], 786.7492);
  EXPECT_DOUBLE_EQ(l.bbox[3], 374.0);
  ASSERT_TRUE(l.score.has_value());
  EXPECT_DOUBLE_EQ(*l.score, 12.2286);
  EXPECT_DOUBLE_EQ(l.h, 1.5206);
  EXPECT_DOUBLE_EQ(l.w, 1.6824);
  EXPECT_DOUBLE_EQ(l.l, 4.4501);
  EXPECT_DOUBLE_EQ(l.x, 2.9312);
  EXPECT_DOUBLE_EQ(l.y, 1.6089);
  EXPECT_DOUBLE_EQ(l.z, 6.4281);
  EXPECT_DOUBLE_EQ(l.rotation_y, -1.5828);
  EXPECT_DOUBLE_EQ(l.alpha, -2.0107);

  EXPECT_EQ(detectDetectionLayout(dir.path()), DetectionLayout::PerClassCsv);
  const auto by_frame = readSequenceDetections(dir.path(), DetectionLayout::PerClassCsv, "0003");
  ASSERT_EQ(by_frame.size(), 2u);
  ASSERT_EQ(by_frame.at(4).size(), 2u);  // the car and the pedestrian of frame 4
  EXPECT_TRUE(readSequenceDetections(dir.path(), DetectionLayout::PerClassCsv, "0009").empty());
}

TEST(Detections, BadLinesNameFileLineAndField) {
  test::TempDir dir;
  write(dir / "Car/0000.txt", "0,2,1,2,3,4,0.5,1,2,3,4,5,6,0.1,0.2\n0,7,1,2,3,4,0.5,1,2,3,4,5,6,0.1,0.2\n");
  const std::string bad_type = test::parseErrorMessage([&] { readPerClassCsvDetections(dir / "Car/0000.txt"); });
  EXPECT_NE(bad_type.find("0000.txt:2"), std::string::npos) << bad_type;
  EXPECT_NE(bad_type.find("type"), std::string::npos) << bad_type;
  write(dir / "Car/0001.txt", "0,2,1,2,3,4,0.5,1,2,3,4,5,6,0.1\n");
  EXPECT_THROW(readPerClassCsvDetections(dir / "Car/0001.txt"), kitti::ParseError);
  write(dir / "Car/0002.txt", "0,2,1,2,x3,4,0.5,1,2,3,4,5,6,0.1,0.2\n");
  const std::string bad_number = test::parseErrorMessage([&] { readPerClassCsvDetections(dir / "Car/0002.txt"); });
  EXPECT_NE(bad_number.find("'x2'"), std::string::npos) << bad_number;
  // Found by fuzzing (test/fuzz/regressions/kitti_io): a frame or type beyond int's range was cast (undefined
  // behaviour) instead of refused.
  write(dir / "Car/0003.txt", "1e68,2,1,2,3,4,0.5,1,2,3,4,5,6,0.1,0.2\n");
  EXPECT_THROW(readPerClassCsvDetections(dir / "Car/0003.txt"), kitti::ParseError);
  write(dir / "Car/0004.txt", "0,4294967298,1,2,3,4,0.5,1,2,3,4,5,6,0.1,0.2\n");
  EXPECT_THROW(readPerClassCsvDetections(dir / "Car/0004.txt"), kitti::ParseError);
}

TEST(Detections, DetectsKittiResultLayouts) {
  test::TempDir object, tracking, empty;
  write(object / "data/000007.txt", "Car -1 -1 0.1 10 20 30 40 1.5 1.6 4 1 1.7 10 0.2 0.93\n");
  write(tracking / "0002.txt", "3 5 Car -1 -1 0.1 10 20 30 40 1.5 1.6 4 1 1.7 10 0.2 0.93\n");
  EXPECT_EQ(detectDetectionLayout(object.path()), DetectionLayout::KittiObject);
  EXPECT_EQ(detectDetectionLayout(tracking.path()), DetectionLayout::KittiTracking);
  EXPECT_THROW(detectDetectionLayout(empty.path()), std::runtime_error);
  const auto frame = readFrameDetections(object.path(), "000007");
  ASSERT_EQ(frame.size(), 1u);
  ASSERT_TRUE(frame[0].score.has_value());
  EXPECT_DOUBLE_EQ(*frame[0].score, 0.93);
  const auto seq = readSequenceDetections(tracking.path(), DetectionLayout::KittiTracking, "0002");
  ASSERT_EQ(seq.at(3).size(), 1u);
  EXPECT_EQ(seq.at(3)[0].track_id, 5);
}

}  // namespace
}  // namespace io
}  // namespace ret3d
