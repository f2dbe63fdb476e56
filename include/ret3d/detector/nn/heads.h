// The two detection heads (LWD-3D's YOLO-style anchor head, a CenterPoint-style centre head): their output layout,
// target assignment, losses and decoding. Torch-level header (detector and train layers only).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <torch/torch.h>

#include "ret3d/core/geometry.h"
#include "ret3d/detector/anchors.h"
#include "ret3d/detector/detector_options.h"
#include "ret3d/detector/nn/network.h"

namespace ret3d {
namespace nn {

// What one training sample should produce.
struct GroundTruth {
  std::vector<Box> boxes;            // objects of the model's classes, in the BEV frame of the sample
  std::vector<bool> velocity_valid;  // per box; empty = all valid (false e.g. for a track seen in one frame only)
  std::vector<Box> ignore;           // regions without objectness/heatmap loss (KITTI DontCare, Van for Car, ...)
  std::vector<BevWedge> ignore_regions;  // more such regions: behind DontCare image boxes (no 3D box in KITTI)
  double supervised_fov_deg = 0;     // > 0: objectness supervised only within +-fov/2 of the x axis
  // Set when the labels exist only inside this wedge (camera 2's view in real KITTI): outside it a cell is neither
  // object nor background. Masked rather than cropped: the network still sees the full 360-degree sweep it gets at
  // inference, and objects at the view's edge keep their points beyond it.
  std::optional<BevWedge> labelled_view;
};

struct HeadLoss {
  torch::Tensor total;
  std::vector<std::pair<std::string, double>> parts;  // for the progress bar: ("obj", 0.12), ...
};

class DetectionHead {
 public:
  virtual ~DetectionHead() = default;
  // Output channels per stride, for building the network.
  virtual std::map<int, int> outputChannels() const = 0;
  // Focal-loss prior on the classification channels of a fresh network.
  virtual void initBias(LwdNetworkImpl& net) const = 0;
  // Assigns targets for the batch and returns the losses. g: the grid of this batch (multi-scale training).
  virtual HeadLoss loss(const NetworkOutput& out, const std::vector<GroundTruth>& gt, const BevGeometry& g,
                        const TrainOptions& train) const = 0;
  // Boxes of one sample of the batch, scored, before NMS (at most max_candidates per class).
  virtual std::vector<Box> decode(const NetworkOutput& out, int sample, const BevGeometry& g,
                                  const InferenceOptions& options) const = 0;
};

// Makes the head the config selects (anchors: used by the anchor head, strides already assigned).
std::unique_ptr<DetectionHead> makeHead(const ModelConfig& config, const std::vector<Anchor>& anchors);

// CenterNet's Gaussian radius (in cells) for a box of the given size in cells at the minimum overlap.
double gaussianRadius(double length_cells, double width_cells, double min_overlap);

// Per-cell loss weight of a map (1 = supervised): 0 inside ignore boxes and regions, outside the supervised field of
// view and outside the labelled view. The heads still teach their positives there.
torch::Tensor supervisionMask(const GroundTruth& gt, const BevGeometry& g, int stride, int h, int w);

}  // namespace nn
}  // namespace ret3d
