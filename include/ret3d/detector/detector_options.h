// Every parameter of the LWD-3D base detector, as plain structs with one loader from YAML
// (config/detector/*.yaml). The `model` part describes what a trained file must be (it is stored in the file and
// compared on load); the `inference` part may change freely at run time; `train` drives `ret3d train detector`.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ret3d/bev/bev_encoder.h"
#include "ret3d/core/ego_box.h"
#include "ret3d/core/option_range.h"
#include "ret3d/core/types.h"
#include "ret3d/detector/point_refine.h"

namespace ret3d {

enum class HeadType { Anchor, Center };
const char* headTypeName(HeadType h);  // "anchor", "center"

// The backbone (LWD-3D §2.3): a stride-2 stem, depthwise-separable stages each halving the resolution (strides 4, 8,
// 16, ...), a transformer block over the coarsest grid, and a decoder (upsample + lateral) back to the output strides.
struct NetworkOptions {
  int stem_channels = 16;
  std::vector<int> stage_channels = {32, 64, 96};
  std::vector<int> stage_blocks = {1, 2, 2};  // depthwise-separable blocks per stage (the first one strides)
  int attention_heads = 4;
  int attention_layers = 1;   // transformer blocks between encoder and decoder (0 = none, for ablation)
  int decoder_channels = 64;  // also the dimension of the per-object feature o_i
  int head_channels = 64;

  // Stride of stage i (0-based): 2^(i + 2).
  int stageStride(int i) const { return 1 << (i + 2); }
  int maxStride() const { return stageStride(static_cast<int>(stage_channels.size()) - 1); }
};

struct AnchorHeadOptions {
  std::vector<int> strides = {4, 8};  // prediction scales (YOLO-style multi-scale)
  int anchors_per_class = 2;          // k of the k-means per class
  // An anchor predicts at the coarsest stride whose cell (stride * resolution) is at most this fraction of its
  // longer side, else at the finest stride.
  double scale_fraction = 0.6;
  int neighbour_cells = 2;            // extra positive cells per object (YOLOv5: the two nearest neighbours)
  // One more channel per anchor predicts the 3D IoU of its decoded box with the object (IoU-aware scoring, as in
  // CIA-SSD and AFDetV2): at inference the score also ranks by how well the box fits, which is what AP at a strict
  // IoU threshold (Car @0.7) rewards.
  bool iou_quality = false;
};

struct CenterHeadOptions {
  int stride = 4;
  double gaussian_overlap = 0.1;  // CenterNet radius from the minimum overlap
  int min_radius = 1;
};

struct ModelConfig {
  std::vector<ObjectClass> classes = {ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::Cyclist};
  BevGeometry geometry;
  double density_norm = 64.0;
  double sweep_interval = 0.1;  // seconds between the two sweeps (velocity targets are per second)
  NetworkOptions network;
  HeadType head = HeadType::Center;
  AnchorHeadOptions anchor;
  CenterHeadOptions center;

  // The output strides of the head in use, finest first.
  std::vector<int> headStrides() const;
  // The stride of the feature map o_i is sampled from (the finest decoder output).
  int featureStride() const { return headStrides().front(); }
  // Throws std::invalid_argument naming the field when inconsistent (grid not divisible by the coarsest stride,
  // a head stride that is not a stage stride, ...).
  void validate() const;
};

// The ground the network runs on (inference.grid_extent), in metres. fromValues() checks its shape once; whether the
// model can run on it (whole cells, divisible by the coarsest stride) needs the model: DetectorOptions::validate().
struct GridExtent {
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;

  // [x_min, x_max, y_min, y_max] as YAML, a ROS parameter or --grid-extent give it. Throws OptionError (key
  // "grid_extent") unless four finite numbers with x_min < x_max and y_min < y_max.
  static GridExtent fromValues(const std::vector<double>& values);
  std::vector<double> values() const { return {x_min, x_max, y_min, y_max}; }
  std::string describe() const;  // "[-80, 80, -48, 48]"
  // `g` over this extent; its resolution and heights kept.
  BevGeometry appliedTo(BevGeometry g) const;
};

// The two-resolution detector: a second model, trained on coarser cells over more ground (e.g. x +-80,
// y +-48 m in 0.5 m cells, config/detector/lwd3d_anchor_far.yaml), runs beside this one. This model's network keeps
// its fine cells over the near field (its grid, or inference.grid_extent); a box whose centre lies inside the near
// field shrunk by `margin` on every side comes from it, any other box from the far model's. Each model's candidates
// go through NMS and voting on their own (a far box overlapping a near one of its class is then dropped), and each box
// is refined and scored by the options of the model it came from (the far model's score calibration is its own, from
// its file). So far cars cost the coarse cells' time, and near ones keep the fine cells.
struct FarFieldOptions {
  std::string model_path;  // a detector model file; a relative path is relative to the near model file's folder
  double margin = 2.0;     // m: near-field boxes this close to its edge (cut off there, seen without context) yield
  static constexpr OptionRange kMargin{0, 20};
};

struct InferenceOptions {
  std::string model_path;      // empty: the network is freshly initialised (tests, training)
  int threads = 2;             // torch intra-op threads and BEV workers
  // The lowest published score: a box scoring less after NMS and refinement is dropped. An uncalibrated class's
  // candidates need it before NMS already (its score does not change after).
  float score_threshold = 0.3f;
  // Per class, a published score other than score_threshold (YAML `class_score_threshold: {Car: 0.4}`): the classes'
  // calibrated scores need not mean the same on real scans. A threshold from outside the model (the pipeline feeding
  // its tracker, --score-threshold, dynamic_reconfigure: setScoreThreshold) applies to every class and clears these.
  std::vector<std::pair<ObjectClass, double>> class_score_threshold;
  // The lowest published score of class c (class_score_threshold, else score_threshold).
  float scoreThreshold(ObjectClass c) const;
  // Every class published from t.
  void setScoreThreshold(float t);
  // "0.5" or "0.5 (Car 0.4)": for logs and captions.
  std::string describeScoreThresholds() const;
  // The network score a candidate of a calibrated class (point_refine.score_calibration) needs before NMS; its
  // calibrated score, from the returns that hold the refined box, must then reach its class's score threshold. A far
  // car's network score is low (few returns in its cells) where its calibrated score need not be. Used as
  // min(candidate_threshold, scoreThreshold(c)).
  float candidate_threshold = 0.05f;
  // The threshold a candidate of class c needs before NMS (the two above).
  float candidateThreshold(ObjectClass c) const;
  int max_candidates = 500;    // per class before NMS
  int max_detections = 200;    // after NMS
  double nms_iou = 0.1;        // rotated BEV IoU, per class
  // Box voting after NMS: each kept box becomes the score-weighted mean of the candidates of its class that overlap
  // it by at least this BEV IoU (itself included); neighbouring cells' predictions sharpen the box. 0 = off.
  double nms_voting_iou = 0.0;
  // With a model that predicts IoU (anchor.iou_quality): score = (objectness * class)^(1 - p) * IoU^p.
  double iou_score_power = 0.5;
  // Box refinement from the raw returns after NMS (point_refine.h); off unless classes are listed.
  PointRefineOptions point_refine;
  // Per class, the speed (m/s) from which a box takes the heading of its velocity (headingFromVelocity); empty = off.
  std::vector<std::pair<ObjectClass, double>> heading_from_velocity;
  // The grid the network runs on; none = the model's. The network is fully convolutional (its attention's positions
  // come from a convolution), so a trained model may cover more ground than it was trained on, at a cost
  // proportional to the area; the resolution and the heights stay the model's.
  std::optional<GridExtent> grid_extent;
  // A far-field model beside this one (FarFieldOptions); none = this model alone.
  std::optional<FarFieldOptions> far_field;
  // The ego vehicle's body in base_link (core/ego_box.h; default KITTI's car): its returns are dropped before the BEV
  // image is made, and a box reaching into it grown by kEgoMargin is dropped after refinement. none (YAML `[]`) = off.
  // The sensor's pose in base_link comes from Detector::setSensorToBase (tf online; KITTI's mount otherwise).
  std::optional<EgoBox> ego_box = EgoBox{};
  static constexpr double kEgoMargin = 0.3;  // m

  // The one allowed range of each number: YAML, the detector nodelet's parameters, cfg/Detector.cfg (a test keeps
  // its ranges equal to these) and the command line all check these.
  static constexpr OptionRange kThreads{1, 64};
  static constexpr OptionRange kScoreThreshold{0, 1};
  static constexpr OptionRange kCandidateThreshold{0, 1};
  static constexpr OptionRange kMaxCandidates{1, 100000};
  static constexpr OptionRange kMaxDetections{1, 100000};
  static constexpr OptionRange kNmsIou{0, 1};  // 0: any overlap with a better box of the class suppresses
  static constexpr OptionRange kNmsVotingIou{0, 1};
  static constexpr OptionRange kIouScorePower{0, 1};
  static constexpr OptionRange kHeadingSpeed{0, std::numeric_limits<double>::infinity()};  // m/s
  // Throws OptionError naming the first value outside its range (its key below `inference:`, e.g. "nms_iou").
  void validate() const;
};

// Sim-to-real augmentation (include/ret3d/train/augmentations.h), applied to each training sample before the
// LWD-3D ones; every part is off by default, and while off draws nothing from the sample's random generator.
struct SensorAugmentOptions {
  // Ray drop: each point of both sweeps is lost with probability p (uniform in [ray_drop_min, ray_drop_max] per
  // sample) plus ray_drop_far * min(1, range / 80 m) (weak far returns); off when both are 0.
  double ray_drop_min = 0.0, ray_drop_max = 0.0;
  double ray_drop_far = 0.0;
  // A box left with fewer points than this by ray drop or beam subsampling (and fewer than it had) becomes an
  // ignore box: neither object nor background.
  int min_box_points = 5;
  // Beam subsampling: with this probability keep every k-th beam only (a 64-beam scan seen as a 32-beam one). The
  // beam of a point is the beam of `beam_sensor` (a sensor YAML, relative to the working directory) whose elevation
  // is nearest the point's, as KITTI scans carry no ring.
  double beam_subsample_probability = 0.0;
  int beam_subsample_keep_every = 2;
  std::string beam_sensor = "config/sensors/hdl64e.yaml";
  // Intensity jitter: with this probability i' = clamp(scale * i^gamma + N(0, sigma)), scale and gamma uniform.
  double intensity_jitter_probability = 0.0;
  double intensity_scale_min = 0.8, intensity_scale_max = 1.2;
  double intensity_gamma_min = 0.8, intensity_gamma_max = 1.25;
  double intensity_noise_sigma = 0.02;
  // Zero intensity: with this probability a fraction uniform in [0, intensity_zero_max] of the points read exactly 0
  // (real HDL-64E scans have 10-16 % such returns, the simulator < 1 %), far points preferred (weight ~ range).
  double intensity_zero_probability = 0.0;
  double intensity_zero_max = 0.2;
  // Per object: with this probability each labelled object's returns (both sweeps) have their intensity multiplied
  // by a gain drawn log-uniformly in [object_intensity_gain_min, object_intensity_gain_max] (clamped to 1). The
  // simulator draws one reflectivity per surface of an actor; real clothing and paint at 905 nm range from dark to
  // bright, so no class should be known by how bright its returns are.
  double object_intensity_probability = 0.0;
  double object_intensity_gain_min = 0.5, object_intensity_gain_max = 2.0;
  // Dark objects: with this probability each labelled object of the object_zero_classes has a fraction, uniform in
  // [object_zero_min, object_zero_max], of its returns (both sweeps) read intensity 0. Real cars at 905 nm (dark and
  // metallic paint, glass) return 0 for most of their points: on the labelled KITTI object frames a car's returns are
  // 64 % zero (median; quartiles 43-72 %), a pedestrian's 8 %, where the simulator's cars give 31 %.
  double object_zero_probability = 0.0;
  double object_zero_min = 0.3, object_zero_max = 0.9;
  std::vector<ObjectClass> object_zero_classes = {ObjectClass::Car};
  // Intensity-free: with this probability every intensity becomes intensity_constant_value.
  double intensity_constant_probability = 0.0;
  double intensity_constant_value = 0.25;
  // Previous-sweep dropout: with this probability the sample loses its previous sweep (as single KITTI object frames
  // have none); its velocity targets become invalid.
  double previous_dropout_probability = 0.0;
  // Sensor pose jitter: height offset uniform in +-pose_z_range (m), pitch and roll each uniform in
  // +-pose_tilt_deg, about the sensor origin, points and boxes alike (boxes keep their yaw).
  double pose_z_range = 0.0;
  double pose_tilt_deg = 0.0;
  // Ground-truth sampling (SECOND): a database written by `ret3d train gtdb` from training folders (or given by
  // `ret3d train detector --gt-database`); up to gt_sample_counts objects per class are pasted per sample at their
  // recorded range and elevation, rotated about the sensor's z axis, where their BEV box grown by gt_sample_margin
  // (m) meets no other box. Off while the path is empty or no count is positive.
  std::string gt_database;
  std::vector<std::pair<ObjectClass, int>> gt_sample_counts;
  double gt_sample_margin = 0.3;

  bool gtSamplingOn() const;
  // Throws OptionError naming the key (as under `train:`) when a value is out of its range.
  void validate() const;
};

struct TrainOptions {
  int epochs = 40;
  int batch_size = 4;
  double learning_rate = 2e-3;
  double weight_decay = 0.01;
  double warmup_fraction = 0.05;  // linear warm-up, then cosine decay
  unsigned seed = 42;
  double checkpoint_minutes = 5.0;
  int max_frames = 0;             // 0 = all frames of the dataset
  // Augmentation (LWD-3D §2.5: rotation, clipping, block input).
  double rotation_range = 0.785;  // global rotation, uniform in +-range (rad)
  bool flip = true;               // mirror about the x axis with probability 0.5
  double scale_min = 0.95, scale_max = 1.05;
  double crop_probability = 0.3;  // drop points outside a random sub-window (random clipping)
  double block_probability = 0.3; // drop points in random blocks (block input)
  // Multi-scale schedule after LWD-3D eq. (4), Scale = 32 (13 + n): here the grid side is 32 (base + n) cells with
  // n drawn from [n_min, n_max] per batch, centred on the sensor (the metric extent changes, the resolution stays, so
  // objects keep their size in cells); n_max < n_min = off (the configured grid).
  int multiscale_base = 12;
  int multiscale_n_min = 0, multiscale_n_max = -1;
  // Place each batch's smaller grid at a random spot inside the configured one (a random crop of the BEV, so that a
  // cheaper grid still trains on far objects) instead of at its centre.
  bool multiscale_random_position = false;
  int threads = 0;                // torch threads while training (0 = inference.threads)
  // Objectness supervised only within +-fov/2 of x (0 = all). A crude stand-in for the labelled view: a camera-view
  // set (`ret3d train detector --labels-cover camera`, or auto) is masked by its calibrated camera frustum instead.
  double supervised_fov_deg = 0.0;
  double loss_weight_regression = 2.0;
  double loss_weight_velocity = 0.5;
  double loss_weight_iou = 1.0;   // the IoU-quality channels (anchor.iou_quality)
  SensorAugmentOptions sensor_augment;  // its keys sit directly under `train:`

  // Throws OptionError naming the key below `train:` when a value is out of its range (sensor_augment's included):
  // the one check of the YAML reader and of `ret3d train detector`'s overrides.
  void validate() const;
};

struct DetectorOptions {
  ModelConfig model;
  InferenceOptions inference;
  TrainOptions train;

  BevEncoderOptions bevOptions() const;
  // The model's geometry with inference.grid_extent applied (what the encoder and the decoding use).
  BevGeometry inferenceGeometry() const;
  // model.validate() (std::invalid_argument), then inference.validate() and whether the network can run on
  // inference.grid_extent (whole cells, divisible by the coarsest stride): OptionError with the key below the
  // document, e.g. "inference.nms_iou", "inference.grid_extent".
  void validate() const;
};

// Reads a YAML file; every key is optional (defaults above); an unknown key, a wrong type or an invalid value
// throws std::runtime_error naming the file and the key.
DetectorOptions loadDetectorOptions(const std::string& path);
DetectorOptions detectorOptionsFromYaml(const std::string& yaml_text, const std::string& origin = "<string>");
// The model part as YAML (stored in model files) and back.
std::string modelConfigToYaml(const ModelConfig& m);
ModelConfig modelConfigFromYaml(const std::string& yaml_text, const std::string& origin);
// Differences between two model configs, one readable line each ("geometry.resolution: 0.25 vs 0.2"); empty = equal.
std::vector<std::string> diffModelConfigs(const ModelConfig& a, const ModelConfig& b);

}  // namespace ret3d
