#include "ret3d/detector/detector_options.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "ret3d/core/yaml_reader.h"

namespace ret3d {

const char* headTypeName(HeadType h) { return h == HeadType::Anchor ? "anchor" : "center"; }

bool SensorAugmentOptions::gtSamplingOn() const {
  if (gt_database.empty()) return false;
  for (const auto& [c, n] : gt_sample_counts)
    if (n > 0) return true;
  return false;
}

std::vector<int> ModelConfig::headStrides() const {
  std::vector<int> s = head == HeadType::Anchor ? anchor.strides : std::vector<int>{center.stride};
  std::sort(s.begin(), s.end());
  return s;
}

void ModelConfig::validate() const {
  auto fail = [](const std::string& m) { throw std::invalid_argument("detector config: " + m); };
  geometry.validate();
  if (classes.empty()) fail("classes must not be empty");
  for (ObjectClass c : classes)
    if (c == ObjectClass::Unknown) fail("classes: Unknown is not a detectable class");
  if (network.stage_channels.empty()) fail("network.stage_channels must not be empty");
  if (network.stage_blocks.size() != network.stage_channels.size())
    fail("network.stage_blocks must have one entry per stage_channels entry");
  for (int b : network.stage_blocks)
    if (b < 1) fail("network.stage_blocks entries must be >= 1");
  if (network.stem_channels < 1 || network.decoder_channels < 1 || network.head_channels < 1)
    fail("network channel counts must be positive");
  if (network.attention_layers > 0 && network.stage_channels.back() % network.attention_heads != 0)
    fail("network.attention_heads must divide the last stage_channels entry");
  const int max_stride = network.maxStride();
  if (geometry.width() % max_stride || geometry.height() % max_stride)
    fail("the grid (" + geometry.describe() + ") must be divisible by the coarsest stride " +
         std::to_string(max_stride));
  const auto strides = headStrides();
  if (strides.empty()) fail("the head needs at least one stride");
  for (int s : strides) {
    bool ok = false;
    for (std::size_t i = 0; i < network.stage_channels.size(); ++i) ok |= network.stageStride(static_cast<int>(i)) == s;
    if (!ok) fail("head stride " + std::to_string(s) + " is not a stage stride (4, 8, ... up to " +
                  std::to_string(max_stride) + ")");
  }
  if (head == HeadType::Anchor && anchor.anchors_per_class < 1) fail("anchor.anchors_per_class must be >= 1");
  if (!(sweep_interval > 0)) fail("sweep_interval must be positive");
}

GridExtent GridExtent::fromValues(const std::vector<double>& v) {
  std::string shown = "[";
  for (std::size_t i = 0; i < v.size(); ++i) shown += (i ? ", " : "") + optionValueText(v[i]);
  shown += "]";
  if (v.size() != 4)
    throw OptionError("grid_extent", shown, "expected [x_min, x_max, y_min, y_max], 4 numbers, not " +
                                                std::to_string(v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw OptionError("grid_extent", shown, "must be finite numbers");
  const GridExtent e{v[0], v[1], v[2], v[3]};
  if (!(e.x_max > e.x_min)) throw OptionError("grid_extent", shown, "x_max must exceed x_min");
  if (!(e.y_max > e.y_min)) throw OptionError("grid_extent", shown, "y_max must exceed y_min");
  return e;
}

std::string GridExtent::describe() const {
  return "[" + optionValueText(x_min) + ", " + optionValueText(x_max) + ", " + optionValueText(y_min) + ", " +
         optionValueText(y_max) + "]";
}

BevGeometry GridExtent::appliedTo(BevGeometry g) const {
  g.x_min = x_min;
  g.x_max = x_max;
  g.y_min = y_min;
  g.y_max = y_max;
  return g;
}

BevGeometry DetectorOptions::inferenceGeometry() const {
  return inference.grid_extent ? inference.grid_extent->appliedTo(model.geometry) : model.geometry;
}

void InferenceOptions::validate() const {
  checkOption("threads", threads, kThreads);
  checkOption("score_threshold", score_threshold, kScoreThreshold);
  for (const auto& [c, t] : class_score_threshold)
    checkOption(std::string("class_score_threshold.") + className(c), t, kScoreThreshold);
  checkOption("candidate_threshold", candidate_threshold, kCandidateThreshold);
  checkOption("max_candidates", max_candidates, kMaxCandidates);
  checkOption("max_detections", max_detections, kMaxDetections);
  checkOption("nms_iou", nms_iou, kNmsIou);
  checkOption("nms_voting_iou", nms_voting_iou, kNmsVotingIou);
  checkOption("iou_score_power", iou_score_power, kIouScorePower);
  for (const auto& [c, speed] : heading_from_velocity)
    checkOption(std::string("heading_from_velocity.") + className(c), speed, kHeadingSpeed);
  if (grid_extent) GridExtent::fromValues(grid_extent->values());
  if (ego_box) EgoBox::fromValues(ego_box->values());
  if (far_field) {
    if (far_field->model_path.empty()) throw OptionError("far_field.model_path", "", "must name a model file");
    checkOption("far_field.margin", far_field->margin, FarFieldOptions::kMargin);
  }
  try {
    point_refine.validate();
  } catch (const std::invalid_argument& e) {
    throw OptionError("point_refine", "", e.what());
  }
}

void SensorAugmentOptions::validate() const {
  const OptionRange unit{0.0, 1.0};
  for (const auto& [key, v] : {std::pair<const char*, double>{"ray_drop_min", ray_drop_min},
                               {"ray_drop_max", ray_drop_max},
                               {"ray_drop_far", ray_drop_far},
                               {"beam_subsample_probability", beam_subsample_probability},
                               {"intensity_jitter_probability", intensity_jitter_probability},
                               {"intensity_zero_probability", intensity_zero_probability},
                               {"intensity_zero_max", intensity_zero_max},
                               {"intensity_constant_probability", intensity_constant_probability},
                               {"intensity_constant_value", intensity_constant_value},
                               {"object_intensity_probability", object_intensity_probability},
                               {"object_zero_probability", object_zero_probability},
                               {"object_zero_min", object_zero_min},
                               {"previous_dropout_probability", previous_dropout_probability}})
    checkOption(key, v, unit);
  if (ray_drop_min > ray_drop_max) throw OptionError("ray_drop_min", "", "must not exceed ray_drop_max");
  checkOption("min_box_points", min_box_points, {0.0});
  checkOption("beam_subsample_keep_every", beam_subsample_keep_every, {2.0});
  if (beam_subsample_probability > 0 && beam_sensor.empty())
    throw OptionError("beam_sensor", "", "a sensor YAML is needed for beam_subsample_probability > 0");
  checkOption("intensity_scale_min", intensity_scale_min, {0.0, 10.0});
  checkOption("intensity_scale_max", intensity_scale_max, {intensity_scale_min, 10.0});
  checkOption("intensity_gamma_min", intensity_gamma_min, {0.1, 10.0});
  checkOption("intensity_gamma_max", intensity_gamma_max, {intensity_gamma_min, 10.0});
  checkOption("intensity_noise_sigma", intensity_noise_sigma, {0.0, 0.5});
  checkOption("object_intensity_gain_min", object_intensity_gain_min, {0.01, 100.0});
  checkOption("object_intensity_gain_max", object_intensity_gain_max, {object_intensity_gain_min, 100.0});
  checkOption("object_zero_max", object_zero_max, {object_zero_min, 1.0});
  checkOption("pose_z_range", pose_z_range, {0.0, 1.0});
  checkOption("pose_tilt_deg", pose_tilt_deg, {0.0, 10.0});
  checkOption("gt_sample_margin", gt_sample_margin, {0.0, 5.0});
  for (const auto& [c, n] : gt_sample_counts)
    checkOption(std::string("gt_sample_counts.") + className(c), n, {0.0, 100.0});
}

void TrainOptions::validate() const {
  checkOption("epochs", epochs, {1.0});
  checkOption("batch_size", batch_size, {1.0});
  checkOption("threads", threads, {0.0, 64.0});
  sensor_augment.validate();
}

float InferenceOptions::scoreThreshold(ObjectClass c) const {
  for (const auto& [k, t] : class_score_threshold)
    if (k == c) return static_cast<float>(t);
  return score_threshold;
}

void InferenceOptions::setScoreThreshold(float t) {
  score_threshold = t;
  class_score_threshold.clear();
}

std::string InferenceOptions::describeScoreThresholds() const {
  std::string classes;
  for (const auto& [c, t] : class_score_threshold)
    classes += (classes.empty() ? "" : ", ") + std::string(className(c)) + " " + optionValueText(t);
  return optionValueText(score_threshold) + (classes.empty() ? "" : " (" + classes + ")");
}

float InferenceOptions::candidateThreshold(ObjectClass c) const {
  for (const auto& [calibrated, weights] : point_refine.score_calibration)
    if (calibrated == c) return std::min(candidate_threshold, scoreThreshold(c));
  return scoreThreshold(c);
}

void DetectorOptions::validate() const {
  model.validate();
  try {
    inference.validate();
  } catch (const OptionError& e) {
    throw e.under("inference");
  }
  if (!inference.grid_extent) return;
  ModelConfig m = model;
  m.geometry = inferenceGeometry();
  try {
    m.validate();
  } catch (const std::invalid_argument& e) {
    throw OptionError("inference.grid_extent", inference.grid_extent->describe(), e.what());
  }
}

BevEncoderOptions DetectorOptions::bevOptions() const {
  BevEncoderOptions o;
  o.geometry = inferenceGeometry();
  o.density_norm = model.density_norm;
  o.threads = inference.threads;
  return o;
}

namespace {

// A map by class name, e.g. centroid: {Pedestrian: 0.1}, ordered by class name: gt_sample_counts draws its classes in
// this order, as it always has.
template <typename V>
void readClassValues(YamlReader& r, const std::string& key, std::vector<std::pair<ObjectClass, V>>* out) {
  if (!r.getClassValues(key, out)) return;
  std::stable_sort(out->begin(), out->end(), [](const auto& a, const auto& b) {
    return std::string(className(a.first)) < className(b.first);
  });
}

void readModel(YamlReader r, ModelConfig* m) {
  r.getClasses("classes", &m->classes);
  {
    YamlReader g = r.child("bev");
    g.get("x_min", &m->geometry.x_min);
    g.get("x_max", &m->geometry.x_max);
    g.get("y_min", &m->geometry.y_min);
    g.get("y_max", &m->geometry.y_max);
    g.get("z_min", &m->geometry.z_min);
    g.get("z_max", &m->geometry.z_max);
    g.get("resolution", &m->geometry.resolution);
    g.get("density_norm", &m->density_norm);
    g.get("sweep_interval", &m->sweep_interval);
    g.finish();
  }
  {
    YamlReader n = r.child("network");
    n.get("stem_channels", &m->network.stem_channels);
    n.get("stage_channels", &m->network.stage_channels);
    n.get("stage_blocks", &m->network.stage_blocks);
    n.get("attention_heads", &m->network.attention_heads);
    n.get("attention_layers", &m->network.attention_layers);
    n.get("decoder_channels", &m->network.decoder_channels);
    n.get("head_channels", &m->network.head_channels);
    n.finish();
  }
  r.getChoice("head", &m->head, {{"anchor", HeadType::Anchor}, {"center", HeadType::Center}});
  {
    YamlReader a = r.child("anchor");
    a.get("strides", &m->anchor.strides);
    a.get("anchors_per_class", &m->anchor.anchors_per_class);
    a.get("scale_fraction", &m->anchor.scale_fraction);
    a.get("neighbour_cells", &m->anchor.neighbour_cells);
    a.get("iou_quality", &m->anchor.iou_quality);
    a.finish();
  }
  {
    YamlReader c = r.child("center");
    c.get("stride", &m->center.stride);
    c.get("gaussian_overlap", &m->center.gaussian_overlap);
    c.get("min_radius", &m->center.min_radius);
    c.finish();
  }
  r.finish();
}

void readInference(YamlReader r, InferenceOptions* o) {
  r.get("model_path", &o->model_path);
  r.get("threads", &o->threads);
  r.get("score_threshold", &o->score_threshold);
  readClassValues(r, "class_score_threshold", &o->class_score_threshold);
  r.get("candidate_threshold", &o->candidate_threshold);
  r.get("max_candidates", &o->max_candidates);
  r.get("max_detections", &o->max_detections);
  r.get("nms_iou", &o->nms_iou);
  r.get("nms_voting_iou", &o->nms_voting_iou);
  r.get("iou_score_power", &o->iou_score_power);
  readClassValues(r, "heading_from_velocity", &o->heading_from_velocity);
  std::vector<double> extent;
  if (r.get("grid_extent", &extent)) {  // checked against the model once it is read (DetectorOptions::validate)
    try {
      o->grid_extent = GridExtent::fromValues(extent);
    } catch (const OptionError& e) {
      r.fail(e.key(), e.reason() + ", got " + e.value());
    }
  }
  std::vector<double> ego;
  if (r.get("ego_box", &ego)) {
    try {
      o->ego_box = ego.empty() ? std::nullopt : std::optional<EgoBox>(EgoBox::fromValues(ego));
    } catch (const OptionError& e) {
      r.fail(e.key(), e.reason() + ", got " + e.value());
    }
  }
  if (r.has("far_field")) {
    YamlReader f = r.child("far_field");
    FarFieldOptions far;
    f.get("model_path", &far.model_path);
    f.get("margin", &far.margin);
    f.finish();
    o->far_field = far;
  }
  {
    YamlReader p = r.child("point_refine");
    p.getClasses("faces", &o->point_refine.faces);
    readClassValues(p, "centroid", &o->point_refine.centroid);
    p.get("centroid_margin", &o->point_refine.centroid_margin);
    p.get("centroid_height", &o->point_refine.centroid_height);
    p.get("vertical_resolution_deg", &o->point_refine.vertical_resolution_deg);
    p.get("quantile", &o->point_refine.quantile);
    p.get("surface_gap", &o->point_refine.surface_gap);
    p.get("margin", &o->point_refine.margin);
    p.get("ground_clearance", &o->point_refine.ground_clearance);
    p.get("max_shift", &o->point_refine.max_shift);
    p.get("min_points", &o->point_refine.min_points);
    p.get("height", &o->point_refine.height);
    p.get("hidden_midpoint", &o->point_refine.hidden_midpoint);
    p.get("grow", &o->point_refine.grow);
    p.get("heading_search_deg", &o->point_refine.heading_search_deg);
    p.get("heading_any", &o->point_refine.heading_any);
    p.get("heading_step_deg", &o->point_refine.heading_step_deg);
    p.get("heading_min_points", &o->point_refine.heading_min_points);
    readClassValues(p, "score_calibration", &o->point_refine.score_calibration);
    p.getClasses("clear_above", &o->point_refine.clear_above);
    p.get("clear_above_gap", &o->point_refine.clear_above_gap);
    p.get("clear_above_height", &o->point_refine.clear_above_height);
    p.get("clear_above_max_returns", &o->point_refine.clear_above_max_returns);
    p.finish();
  }
  r.finish();
  try {
    o->validate();
  } catch (const OptionError& e) {
    r.fail(e.key(), e.value().empty() ? e.reason() : e.reason() + ", got " + e.value());
  }
}

// The sim-to-real augmentation keys (SensorAugmentOptions), directly under `train:`.
void readSensorAugment(YamlReader& r, SensorAugmentOptions* a) {
  r.get("ray_drop_min", &a->ray_drop_min);
  r.get("ray_drop_max", &a->ray_drop_max);
  r.get("ray_drop_far", &a->ray_drop_far);
  r.get("min_box_points", &a->min_box_points);
  r.get("beam_subsample_probability", &a->beam_subsample_probability);
  r.get("beam_subsample_keep_every", &a->beam_subsample_keep_every);
  r.get("beam_sensor", &a->beam_sensor);
  r.get("intensity_jitter_probability", &a->intensity_jitter_probability);
  r.get("intensity_scale_min", &a->intensity_scale_min);
  r.get("intensity_scale_max", &a->intensity_scale_max);
  r.get("intensity_gamma_min", &a->intensity_gamma_min);
  r.get("intensity_gamma_max", &a->intensity_gamma_max);
  r.get("intensity_noise_sigma", &a->intensity_noise_sigma);
  r.get("intensity_zero_probability", &a->intensity_zero_probability);
  r.get("intensity_zero_max", &a->intensity_zero_max);
  r.get("intensity_constant_probability", &a->intensity_constant_probability);
  r.get("intensity_constant_value", &a->intensity_constant_value);
  r.get("object_intensity_probability", &a->object_intensity_probability);
  r.get("object_intensity_gain_min", &a->object_intensity_gain_min);
  r.get("object_intensity_gain_max", &a->object_intensity_gain_max);
  r.get("object_zero_probability", &a->object_zero_probability);
  r.get("object_zero_min", &a->object_zero_min);
  r.get("object_zero_max", &a->object_zero_max);
  r.getClasses("object_zero_classes", &a->object_zero_classes);
  r.get("previous_dropout_probability", &a->previous_dropout_probability);
  r.get("pose_z_range", &a->pose_z_range);
  r.get("pose_tilt_deg", &a->pose_tilt_deg);
  r.get("gt_database", &a->gt_database);
  readClassValues(r, "gt_sample_counts", &a->gt_sample_counts);
  r.get("gt_sample_margin", &a->gt_sample_margin);
}

void readTrain(YamlReader r, TrainOptions* t) {
  r.get("epochs", &t->epochs);
  r.get("batch_size", &t->batch_size);
  r.get("learning_rate", &t->learning_rate);
  r.get("weight_decay", &t->weight_decay);
  r.get("warmup_fraction", &t->warmup_fraction);
  r.get("seed", &t->seed);
  r.get("checkpoint_minutes", &t->checkpoint_minutes);
  r.get("max_frames", &t->max_frames);
  r.get("rotation_range", &t->rotation_range);
  r.get("flip", &t->flip);
  r.get("scale_min", &t->scale_min);
  r.get("scale_max", &t->scale_max);
  r.get("crop_probability", &t->crop_probability);
  r.get("block_probability", &t->block_probability);
  r.get("multiscale_base", &t->multiscale_base);
  r.get("multiscale_n_min", &t->multiscale_n_min);
  r.get("multiscale_n_max", &t->multiscale_n_max);
  r.get("multiscale_random_position", &t->multiscale_random_position);
  r.get("threads", &t->threads);
  r.get("supervised_fov_deg", &t->supervised_fov_deg);
  r.get("loss_weight_regression", &t->loss_weight_regression);
  r.get("loss_weight_velocity", &t->loss_weight_velocity);
  r.get("loss_weight_iou", &t->loss_weight_iou);
  readSensorAugment(r, &t->sensor_augment);
  r.finish();
  try {
    t->validate();
  } catch (const OptionError& e) {
    r.fail(e.key(), e.value().empty() ? e.reason() : e.reason() + ", got " + e.value());
  }
}

void flatten(const YAML::Node& n, const std::string& prefix, std::map<std::string, std::string>* out) {
  if (n.IsMap()) {
    for (const auto& kv : n) flatten(kv.second, prefix.empty() ? kv.first.as<std::string>() : prefix + "." + kv.first.as<std::string>(), out);
  } else {
    YAML::Emitter e;
    e << YAML::Flow << n;
    (*out)[prefix] = e.c_str();
  }
}

}  // namespace

static DetectorOptions readDetectorOptions(YamlReader r) {
  DetectorOptions o;
  readModel(r.child("model"), &o.model);
  readInference(r.child("inference"), &o.inference);
  readTrain(r.child("train"), &o.train);
  r.finish();
  try {
    o.validate();
  } catch (const OptionError& e) {
    r.fail(e.key(), e.value().empty() ? e.reason() : e.reason() + ", got " + e.value());
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  return o;
}

DetectorOptions detectorOptionsFromYaml(const std::string& yaml_text, const std::string& origin) {
  return readDetectorOptions(YamlReader::parse(yaml_text, origin));
}

DetectorOptions loadDetectorOptions(const std::string& path) { return readDetectorOptions(YamlReader::load(path)); }

std::string modelConfigToYaml(const ModelConfig& m) {
  YAML::Emitter e;
  e.SetDoublePrecision(15);  // 0.2 stays "0.2", and still round-trips exactly enough for comparisons
  e << YAML::BeginMap;
  e << YAML::Key << "classes" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (ObjectClass c : m.classes) e << className(c);
  e << YAML::EndSeq;
  e << YAML::Key << "bev" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "x_min" << YAML::Value << m.geometry.x_min << YAML::Key << "x_max" << YAML::Value << m.geometry.x_max;
  e << YAML::Key << "y_min" << YAML::Value << m.geometry.y_min << YAML::Key << "y_max" << YAML::Value << m.geometry.y_max;
  e << YAML::Key << "z_min" << YAML::Value << m.geometry.z_min << YAML::Key << "z_max" << YAML::Value << m.geometry.z_max;
  e << YAML::Key << "resolution" << YAML::Value << m.geometry.resolution;
  e << YAML::Key << "density_norm" << YAML::Value << m.density_norm;
  e << YAML::Key << "sweep_interval" << YAML::Value << m.sweep_interval;
  e << YAML::EndMap;
  e << YAML::Key << "network" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "stem_channels" << YAML::Value << m.network.stem_channels;
  e << YAML::Key << "stage_channels" << YAML::Value << YAML::Flow << m.network.stage_channels;
  e << YAML::Key << "stage_blocks" << YAML::Value << YAML::Flow << m.network.stage_blocks;
  e << YAML::Key << "attention_heads" << YAML::Value << m.network.attention_heads;
  e << YAML::Key << "attention_layers" << YAML::Value << m.network.attention_layers;
  e << YAML::Key << "decoder_channels" << YAML::Value << m.network.decoder_channels;
  e << YAML::Key << "head_channels" << YAML::Value << m.network.head_channels;
  e << YAML::EndMap;
  e << YAML::Key << "head" << YAML::Value << headTypeName(m.head);
  e << YAML::Key << "anchor" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "strides" << YAML::Value << YAML::Flow << m.anchor.strides;
  e << YAML::Key << "anchors_per_class" << YAML::Value << m.anchor.anchors_per_class;
  e << YAML::Key << "scale_fraction" << YAML::Value << m.anchor.scale_fraction;
  e << YAML::Key << "neighbour_cells" << YAML::Value << m.anchor.neighbour_cells;
  e << YAML::Key << "iou_quality" << YAML::Value << m.anchor.iou_quality;
  e << YAML::EndMap;
  e << YAML::Key << "center" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "stride" << YAML::Value << m.center.stride;
  e << YAML::Key << "gaussian_overlap" << YAML::Value << m.center.gaussian_overlap;
  e << YAML::Key << "min_radius" << YAML::Value << m.center.min_radius;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return e.c_str();
}

ModelConfig modelConfigFromYaml(const std::string& yaml_text, const std::string& origin) {
  ModelConfig m;
  readModel(YamlReader::parse(yaml_text, origin, "model"), &m);
  return m;
}

std::vector<std::string> diffModelConfigs(const ModelConfig& a, const ModelConfig& b) {
  std::map<std::string, std::string> fa, fb;
  flatten(YAML::Load(modelConfigToYaml(a)), "", &fa);
  flatten(YAML::Load(modelConfigToYaml(b)), "", &fb);
  std::vector<std::string> out;
  for (const auto& [k, v] : fa) {
    auto it = fb.find(k);
    const std::string w = it == fb.end() ? "<absent>" : it->second;
    if (v != w) out.push_back("model." + k + ": " + v + " vs " + w);
  }
  for (const auto& [k, w] : fb)
    if (!fa.count(k)) out.push_back("model." + k + ": <absent> vs " + w);
  return out;
}

}  // namespace ret3d
