// The optimisation side of InterRM (Ret3D §3.3): batches of tracked sequences, the smooth-L1 regression loss of the
// current box's residuals (L_inter), AdamW steps, input normalisation from the training data, checkpoints. Building
// the sequences (tracker over detections) and the epoch loop live in the train layer (train/inter_trainer.h).
#pragma once

#include <array>
#include <ostream>
#include <vector>

#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/relation_learner.h"

namespace ret3d {
namespace relation {

// One training sequence and the ground truth its current box (sequence.boxes[0]) is regressed to.
struct InterRMSample {
  InterRMSequence sequence;
  Box target;  // same frame as the sequence (the current sensor frame)
};

struct InterRMLoss {
  double total = 0, loc = 0, size = 0, yaw = 0;  // mean smooth-L1 per sequence (loc: dx dy dz, size: 3 logs, yaw)
  std::size_t sequences = 0;
};
std::ostream& operator<<(std::ostream& out, const InterRMLoss& loss);  // its terms: "(loc .. size .. yaw ..)"

// The regression target of a sample: residuals of target w.r.t. sequence.boxes[0], in the current box's frame
// (dx, dy, dz, log l, log w, log h ratios, heading wrapped to [-pi/2, pi/2)), as the network predicts them.
std::array<float, 7> interResiduals(const Box& current, const Box& target);

// fitNormalisation: mean and std of every feature except heading sin/cos and class one-hot; step: a mirror (y -> -y)
// per sequence with probability 0.5 when augment_flip.
using InterRMLearner = RelationLearner<InterRM, InterRMSample, InterRMLoss>;

}  // namespace relation
}  // namespace ret3d
