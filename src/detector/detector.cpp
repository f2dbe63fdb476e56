#include "ret3d/detector/detector.h"

#include <algorithm>
#include <chrono>

#include <torch/torch.h>

#include "ret3d/bev/bev_encoder.h"
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
};

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
}

Detector::Detector(const DetectorOptions& options, std::shared_ptr<nn::DetectorModel> model)
    : options_(options), impl_(std::make_unique<Impl>()) {
  const auto diffs = diffModelConfigs(model->config(), options_.model);
  if (!diffs.empty()) throw std::invalid_argument("Detector: the model does not match the options: " + diffs.front());
  options_.validate();
  impl_->model = std::move(model);
  impl_->encoder = std::make_unique<BevEncoder>(options_.bevOptions());
}

Detector::~Detector() = default;

int Detector::featureDim() const { return impl_->model->metadata().feature_dim; }
std::int64_t Detector::parameterCount() const { return nn::parameterCount(*impl_->model->net); }
nn::DetectorModel& Detector::model() { return *impl_->model; }

Detections Detector::detect(const PointCloud& current, const PointCloud* previous,
                            const Eigen::Isometry3d& prev_to_current) {
  auto t0 = std::chrono::steady_clock::now();
  impl_->encoder->encode(current, previous, prev_to_current, &impl_->bev);
  timings_.bev_ms = msSince(t0);

  torch::NoGradGuard no_grad;
  auto& model = *impl_->model;
  const bool was_training = model.net->is_training();
  model.net->eval();
  t0 = std::chrono::steady_clock::now();
  // from_blob without a copy: the image outlives the forward pass.
  auto input = torch::from_blob(impl_->bev.data.data(), {1, impl_->bev.channels, impl_->bev.height, impl_->bev.width});
  const nn::NetworkOutput out = model.forward(input);
  timings_.network_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  const BevGeometry& g = impl_->encoder->geometry();  // the grid just encoded (inference.grid_extent applied)
  std::vector<Box> candidates = model.head().decode(out, 0, g, options_.inference);
  timings_.decode_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  const auto keep = rotatedNms(candidates, options_.inference.nms_iou, true,
                               static_cast<std::size_t>(std::max(0, options_.inference.max_detections)));
  Detections det;
  if (options_.inference.nms_voting_iou > 0) {
    det.boxes = voteBoxes(candidates, keep, options_.inference.nms_voting_iou);
  } else {
    det.boxes.reserve(keep.size());
    for (std::size_t i : keep) det.boxes.push_back(candidates[i]);
  }
  timings_.nms_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  if (options_.inference.point_refine.enabled()) refineBoxesFromPoints(current, &det.boxes, options_.inference.point_refine);
  headingFromVelocity(&det.boxes, options_.inference.heading_from_velocity);
  // Calibrated classes were let in below score_threshold (candidate_threshold): their final scores decide.
  const float min_score = options_.inference.score_threshold;
  det.boxes.erase(std::remove_if(det.boxes.begin(), det.boxes.end(), [&](const Box& b) { return b.score < min_score; }),
                  det.boxes.end());
  timings_.refine_ms = msSince(t0);

  // The features o_i belong to decoding (Ret3D §3.1): timed with it.
  t0 = std::chrono::steady_clock::now();
  const auto f = nn::sampleFeatures(out.features[0], det.boxes, g, options_.model.featureStride());
  det.feature_dim = static_cast<std::size_t>(f.size(1));
  det.features.assign(f.data_ptr<float>(), f.data_ptr<float>() + f.numel());
  timings_.decode_ms += msSince(t0);
  if (was_training) model.net->train();
  return det;
}

void Detector::setThresholds(double score_threshold, double nms_iou) {
  InferenceOptions next = options_.inference;
  next.score_threshold = static_cast<float>(score_threshold);
  next.nms_iou = nms_iou;
  next.validate();
  options_.inference = next;
}

}  // namespace ret3d
