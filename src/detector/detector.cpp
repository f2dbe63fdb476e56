#include "ret3d/detector/detector.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <numeric>
#include <sstream>

#include <torch/torch.h>

#include "ret3d/bev/bev_encoder.h"
#include "ret3d/core/geometry.h"
#include "ret3d/detector/model_file.h"
#include "ret3d/detector/nms.h"
#include "ret3d/detector/nn/model.h"

namespace ret3d {

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

struct Detector::Impl {
  std::shared_ptr<nn::DetectorModel> model;
  std::unique_ptr<BevEncoder> encoder;
  BevImage bev;
  // The far field (inference.far_field): its model, the inference options its boxes are decoded and refined with
  // (the near model's, but for the score calibration of its own weights, from its file), its encoder and image.
  std::shared_ptr<nn::DetectorModel> far_model;
  InferenceOptions far_inference;
  decltype(PointRefineOptions::score_calibration) far_calibration;
  std::unique_ptr<BevEncoder> far_encoder;
  BevImage far_bev;
  // The ego box (inference.ego_box): the sensor's pose in base_link, and the sweeps with the vehicle's returns removed.
  Eigen::Isometry3d sensor_to_base = defaultSensorToBase();
  PointCloud current_outside, previous_outside;

  void loadFarField(const DetectorOptions& options);
  void setFarInference(const InferenceOptions& near);
  // The current sweep without the vehicle's own returns (ego: inference.ego_box), and previous pointed at the
  // previous one's (in its own sensor frame); the sweeps as given without an ego box.
  const PointCloud& outsideEgoBox(const std::optional<EgoBox>& ego, const PointCloud& current_in,
                                  const PointCloud*& previous);
};

namespace {

std::string farModelPath(const InferenceOptions& o) {
  const std::filesystem::path far(o.far_field->model_path);
  if (far.is_absolute() || o.model_path.empty()) return far.string();
  return (std::filesystem::path(o.model_path).parent_path() / far).string();
}

}  // namespace

void Detector::Impl::loadFarField(const DetectorOptions& options) {
  if (!options.inference.far_field) return;
  const std::string path = farModelPath(options.inference);
  // The file's own model, and the options it was trained with (for its score calibration) when it stores them.
  const ModelFileContents file = readModelFile(path);  // names the file when it is missing or corrupt
  DetectorOptions far;
  if (!file.metadata.trained_with.empty())
    far = detectorOptionsFromYaml(file.metadata.trained_with, path + " (trained_with)");
  far.model = file.metadata.config;
  auto fail = [&](const std::string& why) {
    throw OptionError("inference.far_field.model_path", path, why);
  };
  if (far.inference.far_field) fail("the far-field model has a far field of its own");
  if (far.model.classes != options.model.classes) fail("the far-field model detects other classes");
  far_model = nn::DetectorModel::load(path, &far.model);
  far_model->net->eval();
  if (far_model->metadata().feature_dim != model->metadata().feature_dim)
    fail("its features o_i have " + std::to_string(far_model->metadata().feature_dim) + " values, the near model's " +
         std::to_string(model->metadata().feature_dim));
  far_calibration = far.inference.point_refine.score_calibration;
  DetectorOptions far_grid = far;  // its own grid, with the near model's thread count
  far_grid.inference.threads = options.inference.threads;
  far_encoder = std::make_unique<BevEncoder>(far_grid.bevOptions());
  setFarInference(options.inference);
}

void Detector::Impl::setFarInference(const InferenceOptions& near) {
  far_inference = near;
  far_inference.far_field.reset();
  far_inference.grid_extent.reset();
  far_inference.point_refine.score_calibration = far_calibration;
}

Detector::Detector(const DetectorOptions& options) : options_(options), impl_(std::make_unique<Impl>()) {
  options_.validate();
  torch::set_num_threads(options_.inference.threads);
  if (options_.inference.model_path.empty()) {
    impl_->model = std::make_shared<nn::DetectorModel>(options_.model);
    impl_->model->net->eval();
  } else {
    impl_->model = nn::DetectorModel::load(options_.inference.model_path, &options_.model);
  }
  impl_->encoder = std::make_unique<BevEncoder>(options_.bevOptions());
  impl_->loadFarField(options_);
}

Detector::Detector(const DetectorOptions& options, std::shared_ptr<nn::DetectorModel> model)
    : options_(options), impl_(std::make_unique<Impl>()) {
  const auto diffs = diffModelConfigs(model->config(), options_.model);
  if (!diffs.empty()) throw std::invalid_argument("Detector: the model does not match the options: " + diffs.front());
  options_.validate();
  impl_->model = std::move(model);
  impl_->encoder = std::make_unique<BevEncoder>(options_.bevOptions());
  impl_->loadFarField(options_);
}

Detector::~Detector() = default;

int Detector::featureDim() const { return impl_->model->metadata().feature_dim; }
std::int64_t Detector::parameterCount() const {
  return nn::parameterCount(*impl_->model->net) + (impl_->far_model ? nn::parameterCount(*impl_->far_model->net) : 0);
}
bool Detector::hasFarField() const { return impl_->far_model != nullptr; }

std::string Detector::describeGrids() const {
  std::string s = impl_->encoder->geometry().describe();
  if (!impl_->far_model) return s;
  std::ostringstream far;
  far << s << " near field; far field " << farModelPath(options_.inference) << ": "
      << impl_->far_encoder->geometry().describe() << " beyond " << options_.inference.far_field->margin
      << " m inside the near field's edge";
  return far.str();
}
nn::DetectorModel& Detector::model() { return *impl_->model; }

namespace {

// One model's candidates through rotated NMS, then box voting when nms_voting_iou is set.
std::vector<Box> suppress(const std::vector<Box>& c, const InferenceOptions& o) {
  const auto keep = rotatedNms(c, o.nms_iou, true, static_cast<std::size_t>(std::max(0, o.max_detections)));
  if (o.nms_voting_iou > 0) return voteBoxes(c, keep, o.nms_voting_iou);
  std::vector<Box> kept;
  kept.reserve(keep.size());
  for (std::size_t i : keep) kept.push_back(c[i]);
  return kept;
}

// With a far field the near model owns the boxes centred inside its grid shrunk by the margin, the far model every
// other one.
struct NearFieldShare {
  const BevGeometry& g;
  double margin;
  bool owns(const Box& b) const {
    return b.x >= g.x_min + margin && b.x < g.x_max - margin && b.y >= g.y_min + margin && b.y < g.y_max - margin;
  }
};

// Point refinement and heading from velocity with one model's options.
void refineBoxes(const PointCloud& cloud, const InferenceOptions& o, std::vector<Box>* boxes) {
  if (o.point_refine.enabled()) refineBoxesFromPoints(cloud, boxes, o.point_refine);
  headingFromVelocity(boxes, o.heading_from_velocity);
}

// Calibrated classes were let in below their score thresholds (candidate_threshold): their final scores decide.
// Nothing stands inside or against the vehicle's own body (ego, when set).
void dropLowOrOnEgo(const InferenceOptions& o, const EgoBox* ego, const Eigen::Isometry3d& sensor_to_base,
                    std::vector<Box>* boxes) {
  auto low = [&](const Box& b) {
    return b.score < o.scoreThreshold(b.label) ||
           (ego && ego->touches(b, sensor_to_base, InferenceOptions::kEgoMargin));
  };
  boxes->erase(std::remove_if(boxes->begin(), boxes->end(), low), boxes->end());
}

// The near and far fields' boxes after NMS into one list: the near model's boxes inside its share, the far model's
// outside it except those overlapping a near box of their class across the boundary (they yield to it, as NMS would
// have it). Each model went through NMS and voting on its own, so inside the near field the boxes are the near
// model's as if it ran alone.
void mergeFields(const NearFieldShare& near_share, double nms_iou, std::vector<Box>* near, std::vector<Box>* far) {
  near->erase(std::remove_if(near->begin(), near->end(), [&](const Box& b) { return !near_share.owns(b); }),
              near->end());
  far->erase(std::remove_if(far->begin(), far->end(),
                            [&](const Box& f) {
                              return std::any_of(near->begin(), near->end(), [&](const Box& n) {
                                return n.label == f.label && bevIoU(n, f) > nms_iou;
                              });
                            }),
             far->end());
}

// The far field's boxes and feature rows appended to the near field's, all then in descending score.
void appendFarField(const std::vector<Box>& far_boxes, const torch::Tensor& far_features, std::vector<Box>* boxes,
                    torch::Tensor* features) {
  *features = torch::cat({*features, far_features}, 0);
  boxes->insert(boxes->end(), far_boxes.begin(), far_boxes.end());
  std::vector<std::int64_t> order(boxes->size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::int64_t a, std::int64_t b) { return (*boxes)[a].score > (*boxes)[b].score; });
  std::vector<Box> sorted;
  sorted.reserve(order.size());
  for (std::int64_t i : order) sorted.push_back((*boxes)[i]);
  *boxes = std::move(sorted);
  *features = features->index_select(0, torch::tensor(order, torch::kLong)).contiguous();
}

}  // namespace

const PointCloud& Detector::Impl::outsideEgoBox(const std::optional<EgoBox>& ego, const PointCloud& current_in,
                                                const PointCloud*& previous) {
  if (!ego) return current_in;
  current_outside = current_in;
  removePointsInside(*ego, sensor_to_base, &current_outside);
  if (previous) {
    previous_outside = *previous;
    removePointsInside(*ego, sensor_to_base, &previous_outside);
    previous = &previous_outside;
  }
  return current_outside;
}

Detections Detector::detect(const PointCloud& current_in, const PointCloud* previous_in,
                            const Eigen::Isometry3d& prev_to_current) {
  Impl& im = *impl_;
  const std::optional<EgoBox>& ego = options_.inference.ego_box;
  const PointCloud* previous = previous_in;
  const PointCloud& current = im.outsideEgoBox(ego, current_in, previous);
  const bool far = im.far_model != nullptr;
  auto t0 = std::chrono::steady_clock::now();
  if (far)
    BevEncoder::encodeAll({{im.encoder.get(), &im.bev}, {im.far_encoder.get(), &im.far_bev}}, current, previous,
                          prev_to_current);
  else
    im.encoder->encode(current, previous, prev_to_current, &im.bev);
  timings_.bev_ms = msSince(t0);

  torch::NoGradGuard no_grad;
  auto& model = *im.model;
  const bool was_training = model.net->is_training();
  model.net->eval();
  t0 = std::chrono::steady_clock::now();
  // from_blob without a copy: the image outlives the forward pass.
  auto forward = [](nn::DetectorModel& m, BevImage& bev) {
    return m.forward(torch::from_blob(bev.data.data(), {1, bev.channels, bev.height, bev.width}));
  };
  const nn::NetworkOutput out = forward(model, im.bev);
  nn::NetworkOutput far_out;
  if (far) far_out = forward(*im.far_model, im.far_bev);
  timings_.network_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  const BevGeometry& g = im.encoder->geometry();  // the grid just encoded (inference.grid_extent applied)
  const NearFieldShare near_share{g, far ? options_.inference.far_field->margin : 0.0};
  std::vector<Box> candidates = model.head().decode(out, 0, g, options_.inference);
  std::vector<Box> far_candidates;
  if (far) {  // the far model's candidates outside the near field only
    far_candidates = im.far_model->head().decode(far_out, 0, im.far_encoder->geometry(), im.far_inference);
    far_candidates.erase(std::remove_if(far_candidates.begin(), far_candidates.end(),
                                        [&](const Box& b) { return near_share.owns(b); }),
                         far_candidates.end());
  }
  timings_.decode_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  const InferenceOptions& o = options_.inference;
  Detections det;
  det.boxes = suppress(candidates, o);
  std::vector<Box> far_boxes;
  if (far) {
    far_boxes = suppress(far_candidates, o);
    mergeFields(near_share, o.nms_iou, &det.boxes, &far_boxes);
  }
  timings_.nms_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  // Each box refined and scored by its own model's options.
  refineBoxes(current, o, &det.boxes);
  if (!far_boxes.empty()) refineBoxes(current, im.far_inference, &far_boxes);
  dropLowOrOnEgo(o, ego ? &*ego : nullptr, im.sensor_to_base, &det.boxes);
  dropLowOrOnEgo(o, ego ? &*ego : nullptr, im.sensor_to_base, &far_boxes);
  timings_.refine_ms = msSince(t0);

  // The features o_i belong to decoding (Ret3D §3.1): timed with it. Each box's from its own model's map; the boxes
  // then ordered by descending score, their feature rows with them.
  t0 = std::chrono::steady_clock::now();
  torch::Tensor f = nn::sampleFeatures(out.features[0], det.boxes, g, options_.model.featureStride());
  if (far)
    appendFarField(far_boxes,
                   nn::sampleFeatures(far_out.features[0], far_boxes, im.far_encoder->geometry(),
                                      im.far_model->config().featureStride()),
                   &det.boxes, &f);
  det.feature_dim = static_cast<std::size_t>(f.size(1));
  det.features.assign(f.data_ptr<float>(), f.data_ptr<float>() + f.numel());
  timings_.decode_ms += msSince(t0);
  if (was_training) model.net->train();
  return det;
}

void Detector::setSensorToBase(const Eigen::Isometry3d& sensor_to_base) { impl_->sensor_to_base = sensor_to_base; }
const Eigen::Isometry3d& Detector::sensorToBase() const { return impl_->sensor_to_base; }

void Detector::setThresholds(double score_threshold, double nms_iou) {
  InferenceOptions next = options_.inference;
  next.setScoreThreshold(static_cast<float>(score_threshold));
  next.nms_iou = nms_iou;
  next.validate();
  options_.inference = next;
  if (impl_->far_model) impl_->setFarInference(options_.inference);
}

}  // namespace ret3d
