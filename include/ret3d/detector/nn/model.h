// A complete detector model: config, anchors, network and head; what training optimises and inference runs, and
// what a model file holds. Torch-level header (detector and train layers only).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <torch/torch.h>

#include "ret3d/bev/bev_encoder.h"
#include "ret3d/detector/anchors.h"
#include "ret3d/detector/detector_options.h"
#include "ret3d/detector/model_file.h"
#include "ret3d/detector/nn/heads.h"
#include "ret3d/detector/nn/network.h"

namespace ret3d {
namespace nn {

class DetectorModel {
 public:
  // A freshly initialised model. For the anchor head, `anchors` (e.g. from kmeansAnchors) get their strides here;
  // empty means the typical KITTI sizes.
  DetectorModel(const ModelConfig& config, std::vector<Anchor> anchors = {});

  // Loads a model file; when `expected` is given, refuses (ModelFileError) a file whose model config differs,
  // listing every difference.
  static std::unique_ptr<DetectorModel> load(const std::string& path, const ModelConfig* expected = nullptr);
  // A model of `config` started from the weights of a model file whose config differs at most by outputs that
  // `config` adds (anchor.iou_quality turned on) and by the grid's extent (the cells, heights and network the same:
  // it is fully convolutional): every tensor of the file is copied, a head layer that gained output
  // channels gets the file's in its leading ones. `fresh` (optional) receives the names of tensors not (fully)
  // copied. Throws ModelFileError for any other difference. With other_cell_size the cell size may differ too: the
  // same network on cells of another size sees every object at another scale, so the weights are then a starting
  // point for training, never a model to run as it is.
  static std::unique_ptr<DetectorModel> extend(const std::string& path, const ModelConfig& config,
                                               std::vector<std::string>* fresh = nullptr, bool other_cell_size = false);
  // trained_with: the full config text of the run, stored for the record.
  void save(const std::string& path, const std::string& trained_with = "") const;

  NetworkOutput forward(const torch::Tensor& bev) { return net->forward(bev); }
  ModelMetadata metadata() const;

  const ModelConfig& config() const { return config_; }
  const std::vector<Anchor>& anchors() const { return anchors_; }
  const DetectionHead& head() const { return *head_; }
  LwdNetwork net{nullptr};

 private:
  ModelConfig config_;
  std::vector<Anchor> anchors_;
  std::unique_ptr<DetectionHead> head_;
};

// The BEV image as a 1 x C x H x W tensor (copied).
torch::Tensor bevToTensor(const BevImage& img);

// Bilinear samples of a C x h x w feature map at the centres of the boxes (Ret3D §3.1's o_i): rows of the result
// (boxes.size() x C). Outside the map the nearest border value is used.
torch::Tensor sampleFeatures(const torch::Tensor& features, const std::vector<Box>& boxes, const BevGeometry& g,
                             int stride);

}  // namespace nn
}  // namespace ret3d
