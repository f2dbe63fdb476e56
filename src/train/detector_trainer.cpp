#include "ret3d/train/detector_trainer.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <random>
#include <sstream>

#include <torch/torch.h>
#include <yaml-cpp/yaml.h>

#include "ret3d/bev/bev_encoder.h"
#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/core/yaml_reader.h"
#include "ret3d/detector/anchors.h"
#include "ret3d/detector/nn/model.h"
#include "ret3d/train/augmentations.h"
#include "ret3d/train/detector_dataset.h"

namespace ret3d {

namespace {

struct Checkpoint {
  int epoch = 0;  // the epoch in progress
  int batch = 0;  // batches of that epoch already done
  int step = 0;
};

void writeCheckpoint(const std::string& base, const nn::DetectorModel& model, torch::optim::AdamW& optim,
                     const Checkpoint& c, const std::string& config_text) {
  model.save(base + ".ckpt", config_text);
  torch::save(optim, base + ".ckpt.optim");
  YAML::Emitter e;
  e << YAML::BeginMap << YAML::Key << "epoch" << YAML::Value << c.epoch << YAML::Key << "batch" << YAML::Value
    << c.batch << YAML::Key << "step" << YAML::Value << c.step << YAML::EndMap;
  const std::string tmp = base + ".ckpt.state.tmp";
  std::ofstream(tmp) << e.c_str() << "\n";
  std::filesystem::rename(tmp, base + ".ckpt.state");
}

// Learning rate: linear warm-up, then cosine decay to 5 % of the peak.
double learningRate(const TrainOptions& t, int step, int total) {
  const int warm = std::max(1, static_cast<int>(t.warmup_fraction * total));
  if (step < warm) return t.learning_rate * (step + 1) / warm;
  const double p = static_cast<double>(step - warm) / std::max(1, total - warm);
  return t.learning_rate * (0.05 + 0.95 * 0.5 * (1 + std::cos(M_PI * std::min(1.0, p))));
}

// The job's folders with their weights and label covers (each list empty, one value for all, or one per folder).
std::vector<DetectorDataSource> dataSources(const DetectorTrainJob& job) {
  const std::size_t n = job.data_dirs.size();
  auto check = [n](std::size_t given, const char* what) {
    if (given > 1 && given != n)
      throw std::invalid_argument(std::string("train detector: ") + std::to_string(given) + " " + what + " for " +
                                  std::to_string(n) + " data folders (give one for all, or one per folder)");
  };
  check(job.data_weights.size(), "weights");
  check(job.label_cover.size(), "label covers");
  std::vector<DetectorDataSource> out;
  for (std::size_t i = 0; i < n; ++i) {
    DetectorDataSource s;
    s.root = job.data_dirs[i];
    if (!job.data_weights.empty()) s.weight = job.data_weights[job.data_weights.size() == 1 ? 0 : i];
    if (!job.label_cover.empty()) s.cover = job.label_cover[job.label_cover.size() == 1 ? 0 : i];
    out.push_back(s);
  }
  return out;
}

// The training frames: in all, and per folder its layout, label cover, frames, weight and share of an epoch.
void logDataSources(const DetectorDataset& data, const DetectorOptions& o, double drawn) {
  RET3D_INFO("train detector: " << data.size() << " frames, ~" << std::lround(drawn) << " drawn per epoch, head "
                                << headTypeName(o.model.head) << ", grid " << o.model.geometry.describe());
  for (std::size_t k = 0; k < data.sources().size(); ++k) {
    const DetectorDataSource& src = data.sources()[k];
    const double n = data.setSize(k) * src.weight;
    RET3D_INFO("  " << src.root << " (" << data.layout(k) << " layout, labels cover "
                    << labelCoverName(src.cover) << "): " << data.setSize(k) << " frames x weight " << src.weight
                    << " = ~" << std::fixed << std::setprecision(1) << n << " per epoch, " << 100.0 * n / drawn
                    << " % of an epoch" << std::defaultfloat);
  }
}

// Whether ground-truth sampling runs, and from how many objects.
void logGtSampling(const SensorAugmentOptions& o, const SensorAugmenter& augmenter) {
  if (o.gtSamplingOn())
    RET3D_INFO("ground-truth sampling from " << augmenter.databaseSize() << " objects of " << o.gt_database);
  else if (!o.gt_sample_counts.empty())
    RET3D_INFO("train.gt_sample_counts without a database (train.gt_database, --gt-database): "
               "no ground-truth sampling");
}

// A batch's BEV images and ground truth.
struct TrainBatch {
  std::vector<torch::Tensor> inputs;
  std::vector<nn::GroundTruth> gts;
};

// One sample augmented (sensor, then geometry; both from rng), encoded and added to the batch.
void addSample(DetectorSample s, const SensorAugmenter& sensor_augment, const DetectorOptions& o,
               const BevEncoder& encoder, std::mt19937* rng, TrainBatch* batch) {
  const TrainOptions& t = o.train;
  sensor_augment.apply(&s, rng);  // draws nothing while its options are off
  augmentSample(&s, t, o.model.geometry, rng);
  const BevImage img = encoder.encode(s.current, s.has_previous ? &s.previous : nullptr, s.prev_to_current);
  batch->inputs.push_back(nn::bevToTensor(img));
  nn::GroundTruth gt;
  gt.boxes = std::move(s.boxes);
  gt.velocity_valid = std::move(s.velocity_valid);
  gt.ignore = std::move(s.ignore);
  gt.ignore_regions = std::move(s.ignore_regions);
  gt.labelled_view = s.labelled_view;
  gt.supervised_fov_deg = t.supervised_fov_deg;
  batch->gts.push_back(std::move(gt));
}

// One optimiser step on the batch at learning rate lr (gradients clipped to norm 10); returns the loss.
nn::HeadLoss trainStep(nn::DetectorModel& model, torch::optim::AdamW& optim, const TrainBatch& batch, double lr,
                       const BevGeometry& geometry, const TrainOptions& t) {
  for (auto& group : optim.param_groups()) static_cast<torch::optim::AdamWOptions&>(group.options()).lr(lr);
  optim.zero_grad();
  const nn::NetworkOutput out = model.forward(torch::cat(batch.inputs));
  nn::HeadLoss loss = model.head().loss(out, batch.gts, geometry, t);
  loss.total.backward();
  torch::nn::utils::clip_grad_norm_(model.net->parameters(), 10.0);
  optim.step();
  return loss;
}

}  // namespace

namespace {

// The model a run starts from: the checkpoint of an interrupted run (--resume, with its epoch, batch and step in ck),
// the weights of job.init_model extended to the config's outputs, or fresh weights with anchors clustered from the
// training boxes.
std::shared_ptr<nn::DetectorModel> startingModel(const DetectorTrainJob& job, DetectorDataset& data, Checkpoint* ck) {
  const DetectorOptions& o = job.options;
  const TrainOptions& t = o.train;
  const std::string& base = job.out_model;
  std::shared_ptr<nn::DetectorModel> model;
  if (job.resume && std::filesystem::exists(base + ".ckpt.state")) {
    model = nn::DetectorModel::load(base + ".ckpt", &o.model);
    // The one YAML reader: every key required, no other key, each an integer.
    YamlReader st = YamlReader::load(base + ".ckpt.state");
    for (const auto& [key, value] : {std::pair<const char*, int*>{"epoch", &ck->epoch}, {"batch", &ck->batch},
                                      {"step", &ck->step}})
      if (!st.get(key, value)) st.fail(key, "missing");
    st.finish();
    RET3D_INFO("resuming from " << base << ".ckpt at epoch " << ck->epoch + 1 << ", batch " << ck->batch << ", step "
                                << ck->step);
  } else if (!job.init_model.empty()) {
    if (job.resume)
      RET3D_INFO("--resume: no checkpoint at " << base << ".ckpt.state yet; starting from " << job.init_model);
    // The config's model part must match the file's, or only add outputs (extend() refuses otherwise); the anchors
    // come from the file.
    std::vector<std::string> fresh;
    model = nn::DetectorModel::extend(job.init_model, o.model, &fresh, job.init_other_cells);
    RET3D_INFO("starting from the weights of " << job.init_model << " (fresh optimiser and schedule)");
    for (const std::string& name : fresh) RET3D_INFO("  " << name << ": new outputs start freshly initialised");
  } else {
    if (job.resume) RET3D_WARN("--resume: no checkpoint at " << base << ".ckpt.state; starting afresh");
    std::vector<Anchor> anchors;
    if (o.model.head == HeadType::Anchor) {
      anchors = kmeansAnchors(data.allBoxes(), o.model.classes, o.model.anchor.anchors_per_class, t.seed);
      for (const Anchor& a : anchors)
        RET3D_INFO("anchor " << className(a.label) << ": " << a.length << " x " << a.width << " x " << a.height
                             << " at z " << a.z);
    }
    model = std::make_shared<nn::DetectorModel>(o.model, anchors);
  }
  return model;
}

}  // namespace

DetectorTrainResult trainDetector(const DetectorTrainJob& job) {
  const auto wall0 = std::chrono::steady_clock::now();
  const DetectorOptions& o = job.options;
  const TrainOptions& t = o.train;
  o.model.validate();
  torch::set_num_threads(t.threads > 0 ? t.threads : o.inference.threads);
  torch::manual_seed(t.seed);

  DetectorDataset data(dataSources(job), o.model, t.max_frames);
  double drawn = 0;
  for (std::size_t k = 0; k < data.sources().size(); ++k) drawn += data.setSize(k) * data.sources()[k].weight;
  if (drawn <= 0) throw std::invalid_argument("train detector: every data weight is 0");
  logDataSources(data, o, drawn);
  const SensorAugmenter sensor_augment(t.sensor_augment);
  logGtSampling(t.sensor_augment, sensor_augment);

  Checkpoint ck;
  const std::string base = job.out_model;
  std::shared_ptr<nn::DetectorModel> model = startingModel(job, data, &ck);
  model->net->train();
  torch::optim::AdamW optim(model->net->parameters(),
                            torch::optim::AdamWOptions(t.learning_rate).weight_decay(t.weight_decay));
  if (job.resume && ck.step > 0) torch::load(optim, base + ".ckpt.optim");

  // Fractional weights make the epochs' lengths differ; each epoch's order is fixed by (seed, epoch) alone.
  std::vector<int> epoch_batches_n(t.epochs);
  int total_steps = 0;
  for (int e = 0; e < t.epochs; ++e) {
    epoch_batches_n[e] = static_cast<int>((epochOrder(data, t.seed, e).size() + t.batch_size - 1) / t.batch_size);
    total_steps += epoch_batches_n[e];
  }
  ProgressBar bar("train detector", static_cast<std::size_t>(total_steps));
  if (ck.step > 0) bar.skip(static_cast<std::size_t>(ck.step));
  auto last_ckpt = std::chrono::steady_clock::now();
  DetectorTrainResult result;
  BevEncoderOptions enc_opt = o.bevOptions();

  for (int epoch = ck.epoch; epoch < t.epochs; ++epoch) {
    // The order of an epoch and each sample's augmentation depend only on (seed, epoch, position): a resumed run
    // sees exactly the batches the interrupted one would have.
    const std::vector<std::size_t> order = epochOrder(data, t.seed, epoch);
    const int batches_per_epoch = epoch_batches_n[epoch];
    double epoch_loss = 0;
    int epoch_batches = 0;
    for (int b = (epoch == ck.epoch ? ck.batch : 0); b < batches_per_epoch; ++b) {
      std::mt19937 rng(t.seed * 104729u + static_cast<unsigned>(epoch) * 1009u + static_cast<unsigned>(b));
      enc_opt.geometry = multiscaleGeometry(o.model.geometry, t, &rng);
      const BevEncoder encoder(enc_opt);
      TrainBatch batch;
      for (int k = 0; k < t.batch_size; ++k) {
        const std::size_t pos = static_cast<std::size_t>(b) * t.batch_size + k;
        if (pos >= order.size()) break;
        addSample(data.load(order[pos]), sensor_augment, o, encoder, &rng, &batch);
      }
      const nn::HeadLoss loss =
          trainStep(*model, optim, batch, learningRate(t, ck.step, total_steps), enc_opt.geometry, t);
      ++ck.step;
      const double lv = loss.total.item<double>();
      epoch_loss += lv;
      ++epoch_batches;
      std::ostringstream info;
      info << std::fixed << std::setprecision(3) << "ep " << epoch + 1 << "/" << t.epochs << " loss " << lv;
      for (const auto& [name, v] : loss.parts) info << " " << name << " " << v;
      if (job.progress) bar.tick(1, info.str());
      if (!std::isfinite(lv)) throw std::runtime_error("train detector: the loss is not finite at step " + std::to_string(ck.step));
      const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_ckpt).count();
      if (since > 60.0 * t.checkpoint_minutes) {
        writeCheckpoint(base, *model, optim, {epoch, b + 1, ck.step}, job.config_text);
        last_ckpt = std::chrono::steady_clock::now();
      }
    }
    ck.batch = 0;
    if (epoch_batches > 0) result.last_loss = epoch_loss / epoch_batches;
  }
  bar.finish();
  model->net->eval();
  model->save(job.out_model, job.config_text);
  writeCheckpoint(base, *model, optim, {t.epochs, 0, ck.step}, job.config_text);
  result.steps = ck.step;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  RET3D_INFO("train detector: " << ck.step << " steps in " << std::fixed << std::setprecision(0) << result.seconds
                                << " s; model written to " << job.out_model);
  return result;
}

}  // namespace ret3d
