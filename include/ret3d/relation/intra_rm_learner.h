// The optimisation side of IntraRM: batches of frames, the loss of Ret3D eq. (5) (focal classification +
// lambda_1 smooth-L1 location/size + lambda_2 smooth-L1 heading), AdamW steps, input normalisation from the training
// data, checkpoints. Data loading and the epoch loop live in the train layer (train/intra_trainer.h).
#pragma once

#include <ostream>
#include <vector>

#include "ret3d/core/detections.h"
#include "ret3d/relation/intra_rm.h"
#include "ret3d/relation/intra_rm_targets.h"
#include "ret3d/relation/relation_learner.h"

namespace ret3d {
namespace relation {

// One training frame: the detections (boxes + optional features) and their targets.
struct IntraRMFrame {
  Detections detections;
  std::vector<IntraRMTarget> targets;  // one per detection
};

struct IntraRMLoss {
  double total = 0, cls = 0, reg = 0, dir = 0;
  std::size_t positives = 0, nodes = 0;
};
std::ostream& operator<<(std::ostream& out, const IntraRMLoss& loss);  // its terms: "(cls .. reg .. dir ..)"

// fitNormalisation: mean and std of every basic and detector feature (heading sin/cos and one-hot kept as they are),
// and the spread of the regression targets; step: a rotation about the sensor's z axis and a mirror per frame.
using IntraRMLearner = RelationLearner<IntraRM, IntraRMFrame, IntraRMLoss>;

// Fits each class's score calibration (IntraRMArch::score_scale, score_bias: Platt scaling, logistic regression of
// the box's target on its class logit) on `frames` without augmentation, boxes the loss ignores left out, and stores
// it in `model` (its network unchanged; save() writes it). A class without both positives and negatives, or whose
// scores do not rise with its true positives (a warning), keeps the identity. Returns the boxes per class it was
// fitted on.
PerClass<std::size_t> calibrateIntraRMScores(IntraRM* model, const std::vector<IntraRMFrame>& frames);

}  // namespace relation
}  // namespace ret3d
