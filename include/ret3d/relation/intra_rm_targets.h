// Training targets of IntraRM (Ret3D eq. (5)): which ground truth each detection is assigned to, and what the
// classification and regression heads should output for it.
//
// Assignment is class-aware, by rotated BEV IoU (core bevIoU): a detection is compared only with ground-truth boxes
// of its own class and takes the one it overlaps most. Then:
//   - class channel k is 1 when the detection's best BEV IoU with a class-k box reaches cls_pos_iou[k] (so the
//     refined score learns "the benchmark would count this box"); all channels 0 otherwise (a false positive);
//   - the box residuals (centre, log size, heading) toward the assigned box are regressed when the IoU reaches
//     reg_min_iou of the detection's class;
//   - the classification loss ignores a detection that is not a positive but overlaps (BEV IoU >= 0.5) a box the
//     benchmark does not penalise (Van for Car, Person_sitting for Pedestrian), or that lies in a DontCare region:
//     the KITTI evaluation neither rewards nor penalises those, so their labels would only be noise.
#pragma once

#include <array>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/relation/intra_rm_config.h"

namespace ret3d {
namespace relation {

struct IntraRMTarget {
  std::array<float, 3> cls{{0, 0, 0}};  // per class channel (Car, Pedestrian, Cyclist)
  float cls_weight = 1;                 // 0 = ignored by the classification loss
  bool regress = false;
  float dx = 0, dy = 0, dz = 0;         // ground-truth centre minus detection centre (m)
  float dl = 0, dw = 0, dh = 0;         // log(ground-truth size / detection size)
  float dyaw = 0;                       // heading residual in [-pi/4, pi/4]: direction is ignored (as KITTI's IoU),
                                        // and a quarter turn is taken as swapped length and width
  float iou = 0;                        // best class-aware BEV IoU
};

struct FrameGroundTruth {
  std::vector<Box> boxes;          // Car, Pedestrian, Cyclist boxes (other labels are ignored)
  std::vector<Box> similar;        // not penalised: labelled with the class they would be confused with (Van -> Car,
                                   // Person_sitting -> Pedestrian)
};

// One target per detection. `dont_care[i]` (optional, empty = none) marks detections inside a DontCare region.
std::vector<IntraRMTarget> assignIntraRMTargets(const std::vector<Box>& detections, const FrameGroundTruth& gt,
                                                const IntraRMTrainConfig& config,
                                                const std::vector<bool>& dont_care = {});

// Index of a detected class in the per-class arrays (Car 0, Pedestrian 1, Cyclist 2), -1 for Unknown.
int classIndex(ObjectClass c);

}  // namespace relation
}  // namespace ret3d
