// InterRM, the inter-frame relation module of Ret3D (§3.3, eqs. (6)-(9), Fig. 3): each tracked object is refined
// from its own tracked sequence. The sequence's entries (the object's past boxes moved into the current sensor frame,
// and the current box) are encoded by one linear layer (eq. 6), related by multi-head self-attention (eqs. 7-8) and an
// FFN with the residuals of eq. (9); a regression layer predicts the current box's centre, size and heading residuals.
//
// Inputs per entry (the "basic features", before normalisation), expressed in the frame of the current box (origin at
// its centre, x along its heading), which makes the module independent of where the object is:
//   dx, dy, dz (entry centre relative to the current box), log l, log w, log h, sin/cos of the heading relative to the
//   current heading, vx, vy (in the current box's frame), score, class one-hot (3), the time offset dt (s, <= 0) and
//   the entry's range from the sensor. dt as an input is the paper's "implicit" positional encoding (Table 4); the
//   explicit encodings (temporal: sinusoids of dt; spatial: sinusoids of the sensor-frame position) are added to the
//   encoded features D, as the paper does.
// Only the current entry's refined feature is regressed, so the attention is computed for that one query over all
// keys of the sequence (the other queries' outputs would be discarded): exactly the current row of eqs. (8)-(9).
//
// Variable-length sequences are batched with padding and a key padding mask; a padded entry never changes the output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "ret3d/core/option_range.h"
#include "ret3d/core/per_class.h"
#include "ret3d/core/types.h"
#include "ret3d/relation/relation_module.h"

namespace ret3d {
namespace relation {

struct InterRMImpl;  // the torch side: src/relation/inter_rm_network.h

// Table 4's positional encodings. All of them keep dt as an input feature (the implicit encoding); temporal and
// spatial add sinusoids to D on top ("++Temporal", "++Spatial").
enum class InterPositionalEncoding { Implicit, Temporal, Spatial };
const char* positionalEncodingName(InterPositionalEncoding pe);  // "implicit", "temporal", "spatial"

// What defines a trained network; stored in the model file and checked when it is loaded.
struct InterRMArch {
  int c_enc = 256;        // C_enc of eq. (6)
  int heads = 16;         // heads of eq. (8); must divide c_enc
  int ffn_expansion = 2;  // FFN hidden width = ffn_expansion * c_enc (eq. 9)
  InterPositionalEncoding positional_encoding = InterPositionalEncoding::Implicit;
  int max_history = 30;   // entries used per sequence (the newest ones, current included); longer ones are cut
  // Also regress the size (the paper regresses "the locations and heading degrees" only, §3.3). On the KITTI
  // PointRCNN boxes the learned size residuals did not carry over to held-out sequences (docs/RESULTS.md).
  bool regress_size = true;

  // Ranges (core/option_range.h), checked by validate() alone.
  static constexpr OptionRange kCEnc{4, 4096};  // and a multiple of 4 (sinusoidal encodings)
  static constexpr OptionRange kHeads{1, 4096};  // and a divisor of c_enc
  static constexpr OptionRange kFfnExpansion{1, 16};
  static constexpr OptionRange kMaxHistory{1, 10000};

  void validate() const;  // throws OptionError (a std::invalid_argument) naming the field
};

struct InterRMTrainConfig {
  int epochs = 8;
  int sequences_per_batch = 64;
  double lr = 3e-4;  // AdamW, as the paper
  double weight_decay = 0.01;
  double smooth_l1_beta = 0.1;  // smooth-L1 transition point (residual units: m, log-ratio, rad)
  // The current box is regressed towards its class-aware best BEV-IoU ground truth when the IoU reaches this
  // (Car, Pedestrian, Cyclist): the assignment IntraRM uses.
  PerClass<double> reg_min_iou{0.5, 0.3, 0.3};
  bool augment_flip = true;  // mirror y with probability 0.5
  std::uint64_t seed = 1;

  static constexpr OptionRange kLr{0, std::numeric_limits<double>::infinity(), true};
  static constexpr OptionRange kNonNegative{0, std::numeric_limits<double>::infinity()};  // weight_decay, epochs
  static constexpr OptionRange kSequencesPerBatch{1, std::numeric_limits<double>::infinity()};
  static constexpr OptionRange kSmoothL1Beta{0, std::numeric_limits<double>::infinity(), true};
  static constexpr OptionRange kIou{0, 1, true};  // reg_min_iou

  void validate() const;  // throws OptionError naming the field
};

using InterRMConfig = RelationConfig<InterRMArch, InterRMTrainConfig>;

// Reads a YAML file with optional sections `model:` and `train:`; missing keys keep their defaults; unknown keys and
// bad values throw std::invalid_argument naming them (a missing/unparsable file: std::runtime_error).
InterRMConfig loadInterRMConfig(const std::string& path);
InterRMConfig parseInterRMConfig(const std::string& yaml_text, const std::string& source = "<string>");

// One track's sequence S_i, in the current sensor frame, NEWEST FIRST: boxes[0] is the current (tracked) box, the
// others its past boxes; dt[k] is the time of entry k minus now (s, dt[0] = 0, decreasing).
struct InterRMSequence {
  std::vector<Box> boxes;
  std::vector<double> dt;
};

struct InterRMOptions {
  std::string model_path;  // a model file written by `ret3d train inter` (or InterRM::save)
  int threads = 0;         // > 0: torch::set_num_threads(threads) when the module is created
  // Optional expectations checked against the model file (a mismatch is refused, saying what differs):
  int c_enc = -1;                   // < 0: any
  std::string positional_encoding;  // empty: any; else "implicit", "temporal" or "spatial"
};

class InterRM : public RelationModule<InterRMImpl, InterRMConfig> {
 public:
  // Loads options.model_path (errors: RelationModule's, or an expectation of `options` the file does not meet).
  explicit InterRM(const InterRMOptions& options);
  explicit InterRM(const InterRMArch& arch, std::uint64_t seed = 1) : RelationModule(arch, seed) {}

  // Refines the current box of every sequence; returns one box per sequence: boxes[0] with refined centre, heading
  // and (arch().regress_size) size (residuals; the heading residual is within [-pi/2, pi/2)), everything else (score,
  // label, velocity, track id, point count) kept. Throws std::invalid_argument for an empty sequence, dt of another
  // length, or non-finite fields.
  std::vector<Box> refine(const std::vector<InterRMSequence>& sequences) const;
};

// Per-entry basic features (see the top of this file), in network order.
inline constexpr int kInterBasicFeatures = 16;
// Entry `k` of `seq` in the frame of seq.boxes[0].
void interBasicFeatures(const InterRMSequence& seq, std::size_t k, float* out);

using InterRMModelInfo = ModelInfo<InterRMConfig>;
// Reads only the metadata of a model file (same checks as the constructor, without building the network).
InterRMModelInfo readInterRMModelInfo(const std::string& path);

}  // namespace relation
}  // namespace ret3d
