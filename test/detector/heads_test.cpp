// The heads' tensor layout: a head map written from a box's targets decodes back to that box (both heads), and the
// losses fall when the prediction matches the targets.
#include "ret3d/detector/nn/heads.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "ret3d/detector/box_coder.h"
#include "ret3d/detector/nn/model.h"

namespace ret3d {
namespace {

using torch::indexing::Slice;

ModelConfig smallConfig(HeadType head) {
  ModelConfig m;
  m.geometry.x_min = -16, m.geometry.x_max = 16, m.geometry.y_min = -16, m.geometry.y_max = 16;
  m.geometry.resolution = 0.25;  // 128 x 128
  m.head = head;
  return m;
}

std::vector<Box> someBoxes() {
  Box car;
  car.x = 5.3, car.y = -3.1, car.z = -0.8, car.length = 4.1, car.width = 1.7, car.height = 1.5, car.yaw = 0.7;
  car.vx = 6, car.vy = 2, car.label = ObjectClass::Car;
  Box ped;
  ped.x = -7.9, ped.y = 9.4, ped.z = -0.9, ped.length = 0.7, ped.width = 0.6, ped.height = 1.8, ped.yaw = -2.0;
  ped.vx = -1, ped.vy = 0.5, ped.label = ObjectClass::Pedestrian;
  return {car, ped};
}

float logit(float p) { return std::log(p / (1 - p)); }

void expectFound(const std::vector<Box>& decoded, const Box& b) {
  const Box* best = nullptr;
  for (const auto& d : decoded)
    if (d.label == b.label && (!best || std::hypot(d.x - b.x, d.y - b.y) < std::hypot(best->x - b.x, best->y - b.y)))
      best = &d;
  ASSERT_NE(best, nullptr) << className(b.label);
  EXPECT_NEAR(best->x, b.x, 1e-3);
  EXPECT_NEAR(best->y, b.y, 1e-3);
  EXPECT_NEAR(best->z, b.z, 1e-3);
  EXPECT_NEAR(best->length, b.length, 1e-3);
  EXPECT_NEAR(best->width, b.width, 1e-3);
  EXPECT_NEAR(best->height, b.height, 1e-3);
  EXPECT_NEAR(std::remainder(best->yaw - b.yaw, 2 * M_PI), 0, 1e-3);
  EXPECT_NEAR(best->vx, b.vx, 1e-3);
  EXPECT_NEAR(best->vy, b.vy, 1e-3);
  EXPECT_GT(best->score, 0.9f);
}

TEST(CenterHead, TargetsWrittenIntoTheMapDecodeBackToTheBoxes) {
  const ModelConfig m = smallConfig(HeadType::Center);
  auto head = nn::makeHead(m, {});
  const int s = m.center.stride, C = 3, h = 128 / s, w = 128 / s;
  ASSERT_EQ(head->outputChannels().at(s), C + kBoxCodeSize);
  nn::NetworkOutput out;
  auto raw = torch::full({1, C + kBoxCodeSize, h, w}, 0.0f);
  raw.index_put_({0, Slice(0, C)}, -10.0f);
  for (const Box& b : someBoxes()) {
    const Eigen::Vector2d f = m.geometry.metricToFeature(b.x, b.y, s);
    const int u = static_cast<int>(std::floor(f.x())), v = static_cast<int>(std::floor(f.y()));
    const int c = b.label == ObjectClass::Car ? 0 : 1;
    raw[0][c][v][u] = 10.0f;
    const BoxCode code = encodeCenterBox(b, u, v, s, m.geometry, m.sweep_interval);
    for (int k = 0; k < kBoxCodeSize; ++k) raw[0][C + k][v][u] = code[k];
  }
  out.head[s] = raw;
  InferenceOptions o;
  const auto boxes = head->decode(out, 0, m.geometry, o);
  ASSERT_EQ(boxes.size(), 2u);
  for (const Box& b : someBoxes()) expectFound(boxes, b);

  // The loss of a prediction equal to the targets is far below that of an uninformed one.
  nn::GroundTruth gt;
  gt.boxes = someBoxes();
  TrainOptions t;
  const double good = head->loss(out, {gt}, m.geometry, t).total.item<double>();
  nn::NetworkOutput blank;
  blank.head[s] = torch::zeros_like(raw);
  const double bad = head->loss(blank, {gt}, m.geometry, t).total.item<double>();
  EXPECT_LT(good, 0.2 * bad);
}

// Anchor-head maps that hold `boxes` exactly, each at the first anchor of its class (wherever it lives); with the
// IoU-quality channels, those read `quality_logit` everywhere.
nn::NetworkOutput anchorMaps(const ModelConfig& m, const std::vector<Anchor>& anchors, const std::vector<Box>& boxes,
                             float quality_logit = 0) {
  const int C = 3, D = 1 + C + kBoxCodeSize, Q = m.anchor.iou_quality ? 1 : 0;
  std::map<int, std::vector<Anchor>> per;
  for (const auto& a : anchors) per[a.stride].push_back(a);
  nn::NetworkOutput out;
  for (const auto& [s, an] : per) {
    const int64_t A = static_cast<int64_t>(an.size());
    auto raw = torch::zeros({1, A * (D + Q), 128 / s, 128 / s});
    for (int64_t a = 0; a < A; ++a) raw.index_put_({0, a * D}, -10.0f);
    if (Q) raw.index_put_({0, Slice(A * D, A * (D + 1))}, quality_logit);
    out.head[s] = raw;
  }
  for (const Box& b : boxes) {
    for (const auto& [s, an] : per) {
      for (std::size_t a = 0; a < an.size(); ++a) {
        if (an[a].label != b.label) continue;
        const Eigen::Vector2d f = m.geometry.metricToFeature(b.x, b.y, s);
        const int u = static_cast<int>(std::floor(f.x())), v = static_cast<int>(std::floor(f.y()));
        const BoxCode code = encodeAnchorBox(b, an[a], u, v, s, m.geometry, m.sweep_interval);
        auto raw = out.head[s];
        const int64_t base = static_cast<int64_t>(a) * D;
        raw[0][base][v][u] = 10.0f;                                     // objectness
        raw[0][base + 1 + (b.label == ObjectClass::Car ? 0 : 1)][v][u] = 10.0f;  // class
        raw[0][base + 1 + C + 0][v][u] = logit((code[0] + 0.5f) / 2);   // inverse of 2 sigmoid - 0.5
        raw[0][base + 1 + C + 1][v][u] = logit((code[1] + 0.5f) / 2);
        for (int k = 2; k < kBoxCodeSize; ++k) raw[0][base + 1 + C + k][v][u] = code[k];
        goto next;
      }
    }
  next:;
  }
  return out;
}

TEST(AnchorHead, TargetsWrittenIntoTheMapDecodeBackToTheBoxesAtTheirScale) {
  const ModelConfig m = smallConfig(HeadType::Anchor);
  nn::DetectorModel model(m);  // default anchors, strides assigned
  std::set<int> strides;
  for (const auto& a : model.anchors()) strides.insert(a.stride);
  ASSERT_EQ(strides.size(), 2u);  // cars at stride 8, pedestrians and cyclists at stride 4
  InferenceOptions o;
  const auto boxes = model.head().decode(anchorMaps(m, model.anchors(), someBoxes()), 0, m.geometry, o);
  ASSERT_EQ(boxes.size(), 2u);
  for (const Box& b : someBoxes()) expectFound(boxes, b);
}

TEST(AnchorHead, IoUQualityChannelsRankTheBoxesAndLearnTheOverlap) {
  ModelConfig m = smallConfig(HeadType::Anchor);
  m.anchor.iou_quality = true;
  nn::DetectorModel model(m);
  const int per_anchor = 1 + 3 + kBoxCodeSize;
  for (const auto& [s, ch] : model.head().outputChannels()) EXPECT_EQ(ch % (per_anchor + 1), 0) << "stride " << s;

  // Decoding: the same boxes; the score is (objectness * class)^(1 - p) * IoU^p.
  InferenceOptions o;
  o.iou_score_power = 0.5;
  const auto boxes = model.head().decode(anchorMaps(m, model.anchors(), someBoxes(), 0.0f), 0, m.geometry, o);
  ASSERT_EQ(boxes.size(), 2u);
  for (const Box& d : boxes) EXPECT_NEAR(d.score, std::sqrt(0.5), 1e-3) << className(d.label);  // IoU 0.5, rest ~1
  o.iou_score_power = 0.0;
  for (const Box& d : model.head().decode(anchorMaps(m, model.anchors(), someBoxes(), -3.0f), 0, m.geometry, o))
    EXPECT_GT(d.score, 0.99f);

  // Training: with one anchor per class and no neighbour cells, each box's only positive decodes it exactly, so
  // the IoU target is 1; a channel that says so costs far less than one that says 0.05, and the loss reports it.
  m.anchor.anchors_per_class = 1;
  m.anchor.neighbour_cells = 0;
  nn::DetectorModel one(m);
  nn::GroundTruth gt;
  gt.boxes = someBoxes();
  TrainOptions t;
  auto iouPart = [&](float q) {
    const auto L = one.head().loss(anchorMaps(m, one.anchors(), someBoxes(), q), {gt}, m.geometry, t);
    for (const auto& [name, v] : L.parts)
      if (name == "iou") return v;
    ADD_FAILURE() << "no iou part in the loss";
    return 0.0;
  };
  EXPECT_LT(iouPart(6.0f), 0.1 * iouPart(-3.0f));
}

TEST(Heads, SupervisionMaskHonoursIgnoreBoxesAndFieldOfView) {
  BevGeometry g;
  g.x_min = -8, g.x_max = 8, g.y_min = -8, g.y_max = 8, g.resolution = 1.0;
  nn::GroundTruth gt;
  Box dc;
  dc.x = 4.5, dc.y = 4.5, dc.length = 1.0, dc.width = 1.0, dc.height = 2;
  gt.ignore = {dc};
  gt.supervised_fov_deg = 90;
  auto mask = nn::supervisionMask(gt, g, 1, 16, 16);
  EXPECT_EQ(mask[8 + 4][8 + 4].item<float>(), 0.0f);   // inside the DontCare box
  EXPECT_EQ(mask[8][8 + 6].item<float>(), 1.0f);       // straight ahead
  EXPECT_EQ(mask[8][8 - 6].item<float>(), 0.0f);       // behind: outside +-45 degrees
  EXPECT_EQ(mask[8 + 6][8 + 1].item<float>(), 0.0f);   // to the left
}

}  // namespace
}  // namespace ret3d
