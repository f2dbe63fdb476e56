#include "ret3d/detector/model_file.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "ret3d/detector/box_coder.h"
#include "ret3d/detector/detector.h"
#include "ret3d/detector/nn/model.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

ModelConfig smallModel(HeadType head) {
  ModelConfig m;
  m.geometry.x_min = -16, m.geometry.x_max = 16, m.geometry.y_min = -16, m.geometry.y_max = 16;
  m.network.stage_blocks = {1, 1, 1};
  m.network.decoder_channels = 32;
  m.network.head_channels = 32;
  m.head = head;
  return m;
}

PointCloud someCloud(unsigned seed) {
  PointCloud c;
  std::uint32_t s = seed;
  auto rnd = [&]() { s = s * 1664525u + 1013904223u; return (s >> 8) / 16777216.0f; };
  for (int i = 0; i < 5000; ++i) c.push_back({rnd() * 32 - 16, rnd() * 32 - 16, rnd() * 3 - 2.5f, rnd()});
  return c;
}

std::string readAll(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

void writeAll(const std::string& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

class ModelFileTest : public ::testing::TestWithParam<HeadType> {};

TEST_P(ModelFileTest, SaveThenLoadGivesIdenticalOutputs) {
  test::TempDir dir;
  torch::manual_seed(5);
  DetectorOptions o;
  o.model = smallModel(GetParam());
  o.inference.score_threshold = 0.0f;  // an untrained net: keep candidates so boxes and features are compared
  o.inference.max_detections = 50;
  auto model = std::make_shared<nn::DetectorModel>(o.model);
  // Move the BatchNorm statistics off their defaults so the buffers are part of what must survive.
  model->net->train();
  { torch::NoGradGuard ng; model->forward(torch::rand({2, 6, 128, 128})); }
  model->net->eval();
  const std::string path = dir / "m.ret3d";
  model->save(path, "train: {epochs: 1}\n");

  Detector a(o, model);
  o.inference.model_path = path;
  Detector b(o);
  const PointCloud cur = someCloud(1), prev = someCloud(2);
  const Eigen::Isometry3d T(Eigen::Translation3d(0.5, 0, 0));
  const Detections da = a.detect(cur, &prev, T), db = b.detect(cur, &prev, T);
  ASSERT_FALSE(da.boxes.empty());
  ASSERT_EQ(da.boxes.size(), db.boxes.size());
  for (std::size_t i = 0; i < da.boxes.size(); ++i) {
    EXPECT_EQ(da.boxes[i].x, db.boxes[i].x);
    EXPECT_EQ(da.boxes[i].yaw, db.boxes[i].yaw);
    EXPECT_EQ(da.boxes[i].score, db.boxes[i].score);
    EXPECT_EQ(da.boxes[i].label, db.boxes[i].label);
  }
  EXPECT_EQ(da.feature_dim, 32u);
  EXPECT_EQ(da.features, db.features);
  const ModelMetadata meta = readModelFile(path).metadata;
  EXPECT_EQ(meta.feature_dim, 32);
  EXPECT_EQ(meta.trained_with, "train: {epochs: 1}\n");
  EXPECT_EQ(meta.anchors.size(), GetParam() == HeadType::Anchor ? 6u : 0u);
  EXPECT_EQ(meta.parameter_count, b.parameterCount());
}

INSTANTIATE_TEST_SUITE_P(BothHeads, ModelFileTest, ::testing::Values(HeadType::Center, HeadType::Anchor));

TEST(ModelFile, OtherMetadataIsRefusedSayingWhatDiffers) {
  test::TempDir dir;
  const std::string path = dir / "m.ret3d";
  nn::DetectorModel(smallModel(HeadType::Center)).save(path);
  DetectorOptions o;
  o.model = smallModel(HeadType::Center);
  o.model.geometry.resolution = 0.125;
  o.model.classes = {ObjectClass::Car, ObjectClass::Pedestrian};
  o.inference.model_path = path;
  const std::string m = test::errorMessage<ModelFileError>([&] { Detector d(o); });
  EXPECT_NE(m.find("model.bev.resolution: 0.25 vs 0.125"), std::string::npos) << m;
  EXPECT_NE(m.find("model.classes: [Car, Pedestrian, Cyclist] vs [Car, Pedestrian]"), std::string::npos) << m;
  o.model = smallModel(HeadType::Anchor);
  EXPECT_THROW(Detector{o}, ModelFileError);
}

// A file whose metadata describes a network that cannot be built (here an anchor at a stride the head lacks, as
// fuzz_smoke found) is refused like any other bad file: a ModelFileError that names the file.
TEST(ModelFile, MetadataForANetworkThatCannotBeBuiltIsRefusedNamingTheFile) {
  test::TempDir dir;
  const std::string path = dir / "m.ret3d";
  nn::DetectorModel(smallModel(HeadType::Anchor)).save(path);
  ModelFileContents file = readModelFile(path);
  ASSERT_FALSE(file.metadata.anchors.empty());
  file.metadata.anchors.front().stride = 1;
  writeModelFile(path, file.metadata, file.weights);
  const std::string m = test::errorMessage<ModelFileError>([&] { nn::DetectorModel::load(path); });
  EXPECT_NE(m.find(path), std::string::npos) << m;
  EXPECT_NE(m.find("stride 1"), std::string::npos) << m;
}

TEST(ModelFile, AModelThatAddsIoUQualityStartsFromTheWeightsOfOneWithout) {
  test::TempDir dir;
  const std::string path = dir / "m.ret3d";
  torch::manual_seed(3);
  nn::DetectorModel plain(smallModel(HeadType::Anchor));
  plain.save(path);
  ModelConfig with = smallModel(HeadType::Anchor);
  with.anchor.iou_quality = true;
  std::vector<std::string> fresh;
  auto extended = nn::DetectorModel::extend(path, with, &fresh);
  EXPECT_EQ(fresh, (std::vector<std::string>{"head4.1.weight", "head4.1.bias", "head8.1.weight", "head8.1.bias"}));
  EXPECT_EQ(extended->anchors().size(), plain.anchors().size());
  // Every output the file had comes out the same; the IoU channels follow them.
  plain.net->eval();
  extended->net->eval();
  torch::NoGradGuard ng;
  const auto x = torch::rand({1, 6, 128, 128});
  const auto a = plain.forward(x), b = extended->forward(x);
  for (const auto& [stride, out] : a.head) {
    const auto& ext = b.head.at(stride);
    EXPECT_EQ(ext.size(1), out.size(1) + out.size(1) / (1 + 3 + kBoxCodeSize));
    EXPECT_TRUE(torch::equal(ext.narrow(1, 0, out.size(1)), out)) << "stride " << stride;
  }
  // The reverse (dropping outputs) and any other difference are refused, saying what differs.
  const std::string with_path = dir / "with.ret3d";
  extended->save(with_path);
  EXPECT_THROW(nn::DetectorModel::extend(with_path, smallModel(HeadType::Anchor)), ModelFileError);
  ModelConfig other = with;
  other.network.head_channels = 16;
  const std::string msg = test::errorMessage<ModelFileError>([&] { nn::DetectorModel::extend(path, other); });
  EXPECT_NE(msg.find("model.network.head_channels: 32 vs 16"), std::string::npos) << msg;
}

TEST(ModelFile, AModelCoversAWiderGridThanItWasTrainedOn) {
  test::TempDir dir;
  const std::string path = dir / "m.ret3d";
  torch::manual_seed(5);
  nn::DetectorModel(smallModel(HeadType::Anchor)).save(path);  // a +-16 m grid

  // Inference: the file's weights on a 64 x 32 m grid; boxes come from the whole of it.
  DetectorOptions o;
  o.model = smallModel(HeadType::Anchor);
  o.inference.model_path = path;
  o.inference.score_threshold = 0.0f;
  o.inference.grid_extent = GridExtent{-32, 32, -16, 16};
  Detector d(o);
  EXPECT_EQ(d.options().inferenceGeometry().width(), 256);
  EXPECT_EQ(d.options().inferenceGeometry().height(), 128);
  PointCloud cloud = someCloud(7);
  for (auto& p : cloud.points) p.x *= 2;
  const Detections det = d.detect(cloud, nullptr, Eigen::Isometry3d::Identity());
  ASSERT_FALSE(det.boxes.empty());
  double far = 0;
  for (const Box& b : det.boxes) {
    far = std::max(far, std::abs(b.x));
    EXPECT_LE(std::abs(b.x), 34.0);
    EXPECT_LE(std::abs(b.y), 18.0);
  }
  EXPECT_GT(far, 20.0) << "no box beyond the trained grid";

  // Training: a model of the wider grid starts from every weight of the file.
  ModelConfig wide = smallModel(HeadType::Anchor);
  wide.geometry.x_min = -32, wide.geometry.x_max = 32;
  std::vector<std::string> fresh;
  auto started = nn::DetectorModel::extend(path, wide, &fresh);
  EXPECT_TRUE(fresh.empty());
  EXPECT_EQ(started->config().geometry.width(), 256);
  auto file = nn::DetectorModel::load(path);
  started->net->eval();
  torch::NoGradGuard ng;
  const auto x = torch::rand({1, 6, 128, 256});
  const auto a = file->forward(x), b = started->forward(x);
  for (const auto& [stride, out] : a.head) EXPECT_TRUE(torch::equal(b.head.at(stride), out)) << "stride " << stride;
  // Another cell size is another network input: refused, unless asked for (a start for training on coarser cells).
  wide.geometry.resolution = 0.5;
  EXPECT_THROW(nn::DetectorModel::extend(path, wide), ModelFileError);
  auto coarse = nn::DetectorModel::extend(path, wide, &fresh, true);
  EXPECT_TRUE(fresh.empty());
  EXPECT_EQ(coarse->config().geometry.width(), 128);
  EXPECT_DOUBLE_EQ(coarse->config().geometry.resolution, 0.5);
}

TEST(ModelFile, TruncatedOrCorruptFilesAreRefused) {
  test::TempDir dir;
  const std::string path = dir / "m.ret3d";
  nn::DetectorModel(smallModel(HeadType::Center)).save(path);
  const std::string good = readAll(path);
  ASSERT_NO_THROW(readModelFile(path));
  auto expectRefused = [&](const std::string& bytes, const std::string& words) {
    writeAll(path, bytes);
    try {
      readModelFile(path);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const ModelFileError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expectRefused(good.substr(0, good.size() / 2), "truncated");
  expectRefused(good.substr(0, good.size() - 3), "truncated");
  expectRefused(good.substr(0, 10), "truncated");
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x5a;
  expectRefused(flipped, "checksum mismatch");
  expectRefused("hello world, not a model", "not a ret3d model file");
  std::string version = good;
  version[8] = 9;
  expectRefused(version, "format version 9");
  expectRefused(good + "x", "unexpected bytes");
  EXPECT_THROW(readModelFile(dir / "missing.ret3d"), ModelFileError);
}

}  // namespace
}  // namespace ret3d
