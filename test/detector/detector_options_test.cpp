#include "ret3d/detector/detector_options.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

// The OptionError `f` throws (an empty one, and a test failure, when it throws none).
template <typename F>
OptionError optionErrorOf(F f) {
  try {
    f();
  } catch (const OptionError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted";
  return OptionError("", "", "");
}

// The error reading a detector YAML text gives ("" when it is accepted).
std::string yamlError(const std::string& yaml) {
  return test::errorOrNothing([&] { detectorOptionsFromYaml(yaml); });
}

TEST(DetectorOptions, ShippedConfigsLoadAndValidate) {
  // Every detector YAML of the repository (training stages, the long-range candidate) loads and validates.
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(RET3D_SOURCE_DIR) + "/config/detector")) {
    if (entry.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(loadDetectorOptions(entry.path().string())) << entry.path();
    ++n;
  }
  EXPECT_GE(n, 8);
  for (const char* name : {"lwd3d_center.yaml", "lwd3d_anchor.yaml"}) {
    const auto o = loadDetectorOptions(std::string(RET3D_SOURCE_DIR) + "/config/detector/" + name);
    EXPECT_EQ(o.model.classes.size(), 3u);
    EXPECT_EQ(o.model.geometry.width(), 384);
    EXPECT_EQ(o.inference.threads, 2);
  }
  EXPECT_EQ(loadDetectorOptions(std::string(RET3D_SOURCE_DIR) + "/config/detector/lwd3d_anchor.yaml").model.head,
            HeadType::Anchor);
}

// The training-stage configs each start from the one before (`base:`): a variant holds only what it changes, and
// reads as its base with those keys laid over it.
TEST(DetectorOptions, StageConfigsReadTheirBaseChain) {
  const std::string dir = std::string(RET3D_SOURCE_DIR) + "/config/detector/";
  const DetectorOptions anchor = loadDetectorOptions(dir + "lwd3d_anchor.yaml");
  const DetectorOptions robust = loadDetectorOptions(dir + "lwd3d_anchor_robust.yaml");
  const DetectorOptions dark = loadDetectorOptions(dir + "lwd3d_anchor_dark.yaml");
  // From lwd3d_anchor.yaml through stage 2 (IoU quality, point refinement), robust (augmentations), selftrain
  // (thresholds) to its own keys (clear_above, object_zero_*, seed).
  EXPECT_FALSE(anchor.model.anchor.iou_quality);
  EXPECT_TRUE(dark.model.anchor.iou_quality);
  EXPECT_TRUE(diffModelConfigs(dark.model, robust.model).empty());
  EXPECT_EQ(dark.model.geometry.width(), 384);
  EXPECT_EQ(dark.inference.point_refine.faces, std::vector<ObjectClass>{ObjectClass::Car});
  EXPECT_FLOAT_EQ(robust.inference.score_threshold, 0.3f);
  EXPECT_FLOAT_EQ(dark.inference.score_threshold, 0.5f);
  EXPECT_FLOAT_EQ(dark.inference.scoreThreshold(ObjectClass::Car), 0.4f);
  EXPECT_FLOAT_EQ(robust.inference.scoreThreshold(ObjectClass::Car), 0.3f);
  EXPECT_DOUBLE_EQ(dark.train.sensor_augment.ray_drop_max, 0.3);
  EXPECT_DOUBLE_EQ(anchor.train.sensor_augment.object_zero_probability, 0.0);
  EXPECT_DOUBLE_EQ(dark.train.sensor_augment.object_zero_probability, 0.3);
  EXPECT_EQ(dark.train.seed, 45u);
  EXPECT_DOUBLE_EQ(dark.train.learning_rate, 0.0002);  // selftrain's
  // The far field: lwd3d_anchor_long.yaml's +-80 m grid in its own 0.5 m cells.
  const DetectorOptions far = loadDetectorOptions(dir + "lwd3d_anchor_far.yaml");
  EXPECT_DOUBLE_EQ(far.model.geometry.resolution, 0.5);
  EXPECT_EQ(far.model.geometry.width(), 320);
  EXPECT_EQ(far.model.geometry.height(), 192);
  EXPECT_EQ(far.train.epochs, 10);
}

TEST(DetectorOptions, ValuesAreReadAndDefaultsKept) {
  const auto o = detectorOptionsFromYaml(
      "model:\n  head: anchor\n  bev: {resolution: 0.5, x_min: -32, x_max: 32}\n  network: {decoder_channels: 32}\n"
      "inference: {score_threshold: 0.5}\ntrain: {epochs: 3}\n");
  EXPECT_EQ(o.model.head, HeadType::Anchor);
  EXPECT_DOUBLE_EQ(o.model.geometry.resolution, 0.5);
  EXPECT_EQ(o.model.geometry.width(), 128);
  EXPECT_EQ(o.model.geometry.height(), 192);  // y keeps its default extent
  EXPECT_EQ(o.model.network.decoder_channels, 32);
  EXPECT_FLOAT_EQ(o.inference.score_threshold, 0.5f);
  EXPECT_EQ(o.train.epochs, 3);
  EXPECT_EQ(o.train.batch_size, TrainOptions().batch_size);
}

TEST(DetectorOptions, MistakesAreRefusedNamingTheFileAndKey) {
  test::TempDir dir;
  const std::string path = dir / "bad.yaml";
  std::ofstream(path) << "model:\n  bev:\n    resolutoin: 0.2\n";
  const std::string msg = test::errorMessage([&] { loadDetectorOptions(path); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("key 'model.bev.resolutoin': unknown key"), std::string::npos) << msg;
  EXPECT_THROW(detectorOptionsFromYaml("model: {head: yolo}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("model: {classes: [Car, Truck]}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("model: {bev: {resolution: abc}}"), std::runtime_error);
  // 96 m / 0.35 m is not a whole number of cells; 90 m / 0.25 m = 360 cells is not divisible by the stride 16.
  EXPECT_THROW(detectorOptionsFromYaml("model: {bev: {resolution: 0.35}}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("model: {bev: {x_min: -45, x_max: 45}}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("model: {head: center, center: {stride: 2}}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("model: {bev: {x_min: 0, x_max: 0}}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("inference: {score_threshold: 1.5}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("inference: {candidate_threshold: -0.1}"), std::runtime_error);
}

TEST(DetectorOptions, TheInferenceGridExtentIsReadAndChecked) {
  const auto o = detectorOptionsFromYaml("inference: {grid_extent: [-80, 80, -48, 48]}\n");
  EXPECT_EQ(o.model.geometry.width(), 384);  // the model's grid is unchanged
  EXPECT_EQ(o.inferenceGeometry().width(), 640);
  EXPECT_EQ(o.inferenceGeometry().height(), 384);
  EXPECT_EQ(o.bevOptions().geometry.width(), 640);
  EXPECT_DOUBLE_EQ(o.inferenceGeometry().resolution, o.model.geometry.resolution);
  EXPECT_EQ(detectorOptionsFromYaml("{}").inferenceGeometry().width(), 384);
  auto refused = [](const std::string& yaml, const std::string& words) {
    try {
      detectorOptionsFromYaml(yaml);
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("inference.grid_extent"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused("inference: {grid_extent: [-80, 80]}", "[x_min, x_max, y_min, y_max]");
  refused("inference: {grid_extent: [-45, 45, -48, 48]}", "divisible");  // 360 cells: not a multiple of 16
  refused("inference: {grid_extent: [80, -80, -48, 48]}", "x_max must exceed x_min");
}

TEST(DetectorOptions, TheFarFieldIsReadAndChecked) {
  const auto o = detectorOptionsFromYaml(
      "inference: {grid_extent: [-32, 32, -32, 32], far_field: {model_path: detector_far.pt, margin: 1.5}}\n");
  ASSERT_TRUE(o.inference.far_field);
  EXPECT_EQ(o.inference.far_field->model_path, "detector_far.pt");
  EXPECT_DOUBLE_EQ(o.inference.far_field->margin, 1.5);
  EXPECT_EQ(o.inferenceGeometry().width(), 256);  // the near field: the grid this model's network runs on
  EXPECT_FALSE(detectorOptionsFromYaml("{}").inference.far_field);
  auto refused = [](const std::string& yaml, const std::string& words) {
    try {
      detectorOptionsFromYaml(yaml);
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused("inference: {far_field: {margin: 2}}", "far_field.model_path");
  refused("inference: {far_field: {model_path: f.pt, margin: -1}}", "far_field.margin");
  refused("inference: {far_field: {model_path: f.pt, margins: 1}}", "margins");
}

TEST(DetectorOptions, ModelConfigRoundTripsAndDiffsReadably) {
  ModelConfig m;
  m.head = HeadType::Anchor;
  m.geometry.resolution = 0.2;
  m.geometry.x_min = -51.2, m.geometry.x_max = 51.2, m.geometry.y_min = -51.2, m.geometry.y_max = 51.2;
  const ModelConfig back = modelConfigFromYaml(modelConfigToYaml(m), "test");
  EXPECT_TRUE(diffModelConfigs(m, back).empty());
  ModelConfig other = m;
  other.geometry.resolution = 0.25;
  other.classes = {ObjectClass::Car};
  const auto d = diffModelConfigs(m, other);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0], "model.bev.resolution: 0.2 vs 0.25");
  EXPECT_EQ(d[1], "model.classes: [Car, Pedestrian, Cyclist] vs [Car]");
}

// One range per value: the YAML reader, the nodelet's parameters, dynamic_reconfigure and the command line all refuse
// through InferenceOptions::validate(), naming the key, the value and the range.
TEST(DetectorOptions, EveryInferenceValueHasOneRangeAndARefusalNamesKeyValueAndRange) {
  // nms_iou had no check in YAML (and [0.01, 1] as a ROS parameter): now [0, 1] everywhere.
  EXPECT_EQ(yamlError("inference: {nms_iou: 1.5}"), "<string>: key 'inference.nms_iou': must lie in [0, 1], got 1.5");
  EXPECT_EQ(yamlError("inference: {nms_iou: 0}"), "");
  EXPECT_EQ(yamlError("inference: {max_detections: 0}"),
            "<string>: key 'inference.max_detections': must lie in [1, 100000], got 0");
  EXPECT_EQ(yamlError("inference: {threads: 65}"), "<string>: key 'inference.threads': must lie in [1, 64], got 65");
  EXPECT_EQ(yamlError("inference: {heading_from_velocity: {Car: -1}}"),
            "<string>: key 'inference.heading_from_velocity.Car': must be >= 0, got -1");
  EXPECT_EQ(yamlError("inference: {class_score_threshold: {Car: 1.5}}"),
            "<string>: key 'inference.class_score_threshold.Car': must lie in [0, 1], got 1.5");
  EXPECT_EQ(yamlError("inference: {class_score_threshold: {Car: 0.4}}"), "");

  InferenceOptions o;
  EXPECT_NO_THROW(o.validate());
  o.nms_iou = std::nan("");
  const OptionError e = optionErrorOf([&] { o.validate(); });
  EXPECT_EQ(e.key(), "nms_iou");
  EXPECT_EQ(e.reason(), "must lie in [0, 1]");
  EXPECT_EQ(std::string(e.what()), "nms_iou = nan: must lie in [0, 1]");
  DetectorOptions d;
  d.inference.score_threshold = -0.5f;
  EXPECT_EQ(optionErrorOf([&] { d.validate(); }).key(), "inference.score_threshold");
}

// The training options have one validate() too, which the YAML reader and `ret3d train detector` (after its
// --threads override) call: the same refusal either way.
TEST(DetectorOptions, TrainingValuesHaveOneRangeInYamlAndInValidate) {
  EXPECT_EQ(yamlError("train: {ray_drop_max: 1.5}"), "<string>: key 'train.ray_drop_max': must lie in [0, 1], got 1.5");
  EXPECT_EQ(yamlError("train: {epochs: 0}"), "<string>: key 'train.epochs': must be >= 1, got 0");
  EXPECT_EQ(yamlError("train: {ray_drop_min: 0.2, ray_drop_max: 0.1}"),
            "<string>: key 'train.ray_drop_min': must not exceed ray_drop_max");
  EXPECT_EQ(yamlError("train: {intensity_scale_min: 0.9, intensity_scale_max: 0.8}"),
            "<string>: key 'train.intensity_scale_max': must lie in [0.9, 10], got 0.8");
  EXPECT_EQ(yamlError("train: {epochs: 3, ray_drop_max: 0.3}"), "");

  TrainOptions t;
  EXPECT_NO_THROW(t.validate());
  t.threads = 65;
  EXPECT_EQ(std::string(optionErrorOf([&] { t.validate(); }).what()), "threads = 65: must lie in [0, 64]");
  t.threads = 2;
  t.sensor_augment.gt_sample_counts.emplace_back(ObjectClass::Pedestrian, 101);
  EXPECT_EQ(optionErrorOf([&] { t.validate(); }).key(), "gt_sample_counts.Pedestrian");
}

TEST(DetectorOptions, AGridExtentIsFourFiniteOrderedNumbersAndFitsTheModel) {
  const GridExtent e = GridExtent::fromValues({-80, 80, -48, 48});
  EXPECT_EQ(e.values(), (std::vector<double>{-80, 80, -48, 48}));
  EXPECT_EQ(e.describe(), "[-80, 80, -48, 48]");
  auto reason = [](const std::vector<double>& v) {
    const OptionError e = optionErrorOf([&] { GridExtent::fromValues(v); });
    EXPECT_EQ(e.key(), "grid_extent");
    return e.reason();
  };
  EXPECT_EQ(reason({-80, 80, -48}), "expected [x_min, x_max, y_min, y_max], 4 numbers, not 3");
  EXPECT_EQ(reason({-80, std::numeric_limits<double>::infinity(), -48, 48}), "must be finite numbers");
  EXPECT_EQ(reason({-80, 80, 48, 48}), "y_max must exceed y_min");
  // The shape is fine, but 360 cells are not a multiple of the model's coarsest stride (16): the model decides.
  DetectorOptions d;
  d.inference.grid_extent = GridExtent::fromValues({-45, 45, -48, 48});
  const OptionError err = optionErrorOf([&] { d.validate(); });
  EXPECT_EQ(err.key(), "inference.grid_extent");
  EXPECT_EQ(err.value(), "[-45, 45, -48, 48]");
  EXPECT_NE(err.reason().find("divisible by the coarsest stride 16"), std::string::npos) << err.reason();
  d.inference.grid_extent = GridExtent::fromValues({-64, 64, -48, 48});
  EXPECT_NO_THROW(d.validate());
  EXPECT_EQ(d.inferenceGeometry().width(), 512);
}

}  // namespace
}  // namespace ret3d
