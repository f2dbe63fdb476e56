#include "ret3d/detector/nn/model.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ret3d {
namespace nn {

DetectorModel::DetectorModel(const ModelConfig& config, std::vector<Anchor> anchors)
    : config_(config), anchors_(std::move(anchors)) {
  config_.validate();
  if (config_.head == HeadType::Anchor) {
    if (anchors_.empty()) anchors_ = defaultAnchors(config_.classes, config_.anchor.anchors_per_class);
    if (std::any_of(anchors_.begin(), anchors_.end(), [](const Anchor& a) { return a.stride == 0; }))
      assignAnchorStrides(&anchors_, config_.anchor.strides, config_.geometry.resolution,
                          config_.anchor.scale_fraction);
    // Every scale needs an anchor: an empty scale takes the anchors closest to it in size.
    for (int s : config_.anchor.strides)
      if (std::none_of(anchors_.begin(), anchors_.end(), [&](const Anchor& a) { return a.stride == s; })) {
        auto copy = anchors_;
        for (auto& a : copy) a.stride = s;
        std::vector<Anchor> extra;
        for (ObjectClass c : config_.classes)
          for (auto& a : copy)
            if (a.label == c) {
              extra.push_back(a);
              break;
            }
        anchors_.insert(anchors_.end(), extra.begin(), extra.end());
      }
  } else {
    anchors_.clear();
  }
  head_ = makeHead(config_, anchors_);
  net = LwdNetwork(config_.network, BevEncoder::kChannels, head_->outputChannels());
  head_->initBias(*net);
}

ModelMetadata DetectorModel::metadata() const {
  ModelMetadata m;
  m.config = config_;
  m.anchors = anchors_;
  m.in_channels = BevEncoder::kChannels;
  m.feature_dim = config_.network.decoder_channels;
  m.feature_stride = config_.featureStride();
  m.parameter_count = parameterCount(*net);
  return m;
}

void DetectorModel::save(const std::string& path, const std::string& trained_with) const {
  torch::serialize::OutputArchive archive;
  net->save(archive);
  std::ostringstream os;
  archive.save_to(os);
  ModelMetadata m = metadata();
  m.trained_with = trained_with;
  writeModelFile(path, m, os.str());
}

std::unique_ptr<DetectorModel> DetectorModel::load(const std::string& path, const ModelConfig* expected) {
  ModelFileContents file = readModelFile(path);
  const ModelMetadata& m = file.metadata;
  if (expected) {
    const auto diffs = checkModelMetadata(m, *expected);
    if (!diffs.empty()) {
      std::string msg = path + ": the model does not match the configuration:";
      for (const auto& d : diffs) msg += "\n  " + d;
      throw ModelFileError(msg);
    }
  }
  if (m.in_channels != BevEncoder::kChannels)
    throw ModelFileError(path + ": the model reads " + std::to_string(m.in_channels) +
                         " BEV channels, this build encodes " + std::to_string(BevEncoder::kChannels));
  // The metadata may describe a network that cannot be built (an anchor at a stride the head lacks, ...): the
  // refusal names the file like every other.
  std::unique_ptr<DetectorModel> model;
  try {
    model = std::make_unique<DetectorModel>(m.config, m.anchors);
  } catch (const std::invalid_argument& e) {
    throw ModelFileError(path + ": the metadata describes a network that cannot be built: " + e.what());
  } catch (const c10::Error& e) {
    throw ModelFileError(path + ": the metadata describes a network that cannot be built: " +
                         e.what_without_backtrace());
  }
  if (model->metadata().feature_dim != m.feature_dim || parameterCount(*model->net) != m.parameter_count)
    throw ModelFileError(path + ": the metadata describes " + std::to_string(m.parameter_count) +
                         " parameters, the network built from it has " +
                         std::to_string(parameterCount(*model->net)));
  try {
    torch::serialize::InputArchive archive;
    std::istringstream is(file.weights);
    archive.load_from(is);
    model->net->load(archive);
  } catch (const c10::Error& e) {
    throw ModelFileError(path + ": the weights do not fit the network: " + e.what_without_backtrace());
  }
  model->net->eval();
  return model;
}

std::unique_ptr<DetectorModel> DetectorModel::extend(const std::string& path, const ModelConfig& config,
                                                     std::vector<std::string>* fresh, bool other_cell_size) {
  auto from = load(path);
  ModelConfig base = config;
  base.anchor.iou_quality = from->config().anchor.iou_quality;
  // The network is fully convolutional: a start on a grid of another extent (same cells) keeps every weight.
  const BevGeometry& fg = from->config().geometry;
  base.geometry.x_min = fg.x_min;
  base.geometry.x_max = fg.x_max;
  base.geometry.y_min = fg.y_min;
  base.geometry.y_max = fg.y_max;
  if (other_cell_size) base.geometry.resolution = fg.resolution;
  const auto diffs = diffModelConfigs(from->config(), base);
  if (!diffs.empty() || (from->config().anchor.iou_quality && !config.anchor.iou_quality)) {
    std::string msg = path + ": cannot start the configured model from this file:";
    for (const auto& d : diffs) msg += "\n  " + d + " (file vs config)";
    if (diffs.empty()) msg += "\n  model.anchor.iou_quality: true vs false (the config would drop outputs)";
    throw ModelFileError(msg);
  }
  auto model = std::make_unique<DetectorModel>(config, from->anchors());
  torch::NoGradGuard no_grad;
  const auto source = from->net->named_parameters(true);
  const auto source_buffers = from->net->named_buffers(true);
  auto copy = [&](const std::string& name, torch::Tensor& dst, const torch::Tensor* src) {
    if (!src) {
      if (fresh) fresh->push_back(name);
      return;
    }
    if (src->sizes() == dst.sizes()) {
      dst.copy_(*src);
      return;
    }
    // A layer that gained output channels (dim 0): the old ones lead.
    if (src->dim() == dst.dim() && src->size(0) < dst.size(0) && src->sizes().slice(1) == dst.sizes().slice(1)) {
      dst.narrow(0, 0, src->size(0)).copy_(*src);
      if (fresh) fresh->push_back(name);
      return;
    }
    throw ModelFileError(path + ": tensor " + name + " has an unexpected shape");
  };
  for (auto& p : model->net->named_parameters(true)) copy(p.key(), p.value(), source.find(p.key()));
  for (auto& b : model->net->named_buffers(true)) copy(b.key(), b.value(), source_buffers.find(b.key()));
  return model;
}

torch::Tensor bevToTensor(const BevImage& img) {
  return torch::from_blob(const_cast<float*>(img.data.data()), {1, img.channels, img.height, img.width}).clone();
}

torch::Tensor sampleFeatures(const torch::Tensor& features, const std::vector<Box>& boxes, const BevGeometry& g,
                             int stride) {
  const int C = static_cast<int>(features.size(0)), h = static_cast<int>(features.size(1)),
            w = static_cast<int>(features.size(2));
  auto out = torch::zeros({static_cast<int64_t>(boxes.size()), C});
  if (boxes.empty()) return out;
  auto f = features.contiguous();
  auto fa = f.accessor<float, 3>();
  auto oa = out.accessor<float, 2>();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    // Feature cell (u, v) holds the value at its centre, (u + 0.5, v + 0.5) in continuous feature coordinates.
    const Eigen::Vector2d p = g.metricToFeature(boxes[i].x, boxes[i].y, stride) - Eigen::Vector2d(0.5, 0.5);
    const double px = std::min<double>(w - 1, std::max(0.0, p.x())), py = std::min<double>(h - 1, std::max(0.0, p.y()));
    const int u0 = static_cast<int>(std::floor(px)), v0 = static_cast<int>(std::floor(py));
    const int u1 = std::min(u0 + 1, w - 1), v1 = std::min(v0 + 1, h - 1);
    const float ax = static_cast<float>(px - u0), ay = static_cast<float>(py - v0);
    for (int c = 0; c < C; ++c)
      oa[i][c] = (1 - ay) * ((1 - ax) * fa[c][v0][u0] + ax * fa[c][v0][u1]) +
                 ay * ((1 - ax) * fa[c][v1][u0] + ax * fa[c][v1][u1]);
  }
  return out;
}

}  // namespace nn
}  // namespace ret3d
