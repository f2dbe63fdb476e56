// The epoch loop IntraRM and InterRM train with (src/train/intra_trainer.cpp, inter_trainer.cpp), and what their
// trainers do around it (trainRelationModule): a shuffle that
// depends only on (seed, epoch), so a resumed run sees the same order; mini-batches of pointers into the samples;
// a progress bar with the losses; after each epoch the validation loss, the model saved when it is the best so far,
// and a checkpoint. Without validation samples the last epoch's model is saved.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"

namespace ret3d {
namespace train {

// A loss's terms as its operator<< writes them (at the stream's default precision, whatever the caller's).
template <typename Loss>
std::string terms(const Loss& loss) {
  std::ostringstream o;
  o << loss;
  return o.str();
}

struct EpochLoopSettings {
  std::string name;         // "IntraRM", "InterRM": bar and log prefix
  int start_epoch = 0;      // epochs already done (a resumed run)
  int epochs = 0;           // in all
  std::uint64_t seed = 0;   // the shuffle's
  std::size_t batch_size = 1;
  std::string out_path;     // the model file
  std::string checkpoint;   // the learner's checkpoint path
  bool progress = true;
};

// Learner: step(batch) and evaluate(samples) returning a loss with .total, model().save(path),
// saveCheckpoint(path, epochs_done, best_val). Report: first_train_loss, last_train_loss, val_losses, best_epoch,
// epochs_run. A Loss writes its terms to a stream for the bar and the log, e.g. "(loc 0.1 size 0.2 yaw 0.3)".
// *best_val is the loss to beat (infinity, or the untrained module's) and is updated.
template <typename Learner, typename Sample, typename Loss, typename Report>
void runEpochs(const EpochLoopSettings& s, Learner& learner, const std::vector<Sample>& train,
               const std::vector<Sample>& val, double* best_val, Report* report) {
  const std::size_t bs = std::max<std::size_t>(1, s.batch_size);
  const std::size_t batches = (train.size() + bs - 1) / bs;
  for (int epoch = s.start_epoch; epoch < s.epochs; ++epoch) {
    std::vector<std::size_t> order(train.size());
    std::iota(order.begin(), order.end(), 0);
    std::mt19937_64 rng(s.seed * 1000003ULL + static_cast<std::uint64_t>(epoch));
    std::shuffle(order.begin(), order.end(), rng);
    double sum = 0;
    std::unique_ptr<ProgressBar> bar;
    if (s.progress)
      bar = std::make_unique<ProgressBar>(
          s.name + " epoch " + std::to_string(epoch + 1) + "/" + std::to_string(s.epochs), batches);
    for (std::size_t b = 0; b < batches; ++b) {
      std::vector<const Sample*> batch;
      for (std::size_t k = b * bs; k < std::min(train.size(), (b + 1) * bs); ++k) batch.push_back(&train[order[k]]);
      const Loss L = learner.step(batch);
      if (epoch == s.start_epoch && b == 0) report->first_train_loss = L.total;
      sum += L.total;
      if (bar) {
        std::ostringstream info;
        info.precision(4);
        info << "loss " << L.total << " " << terms(L);
        bar->tick(1, info.str());
      }
    }
    if (bar) bar->finish();
    report->last_train_loss = sum / static_cast<double>(batches);
    std::ostringstream msg;
    msg << s.name << " epoch " << epoch + 1 << ": train loss " << report->last_train_loss;
    if (!val.empty()) {
      const Loss V = learner.evaluate(val);
      report->val_losses.push_back(V.total);
      msg << ", validation loss " << V.total << " " << terms(V);
      if (V.total < *best_val) {
        *best_val = V.total;
        report->best_epoch = epoch + 1;
        learner.model().save(s.out_path);
        msg << " - best, saved";
      }
    }
    RET3D_INFO(msg.str());
    learner.saveCheckpoint(s.checkpoint, epoch + 1, *best_val);
    report->epochs_run = epoch + 1;
  }
  if (val.empty()) {
    learner.model().save(s.out_path);
    report->best_epoch = report->epochs_run;
  }
}

// A relation module's training from its trainer's options (config, out_path, checkpoint_dir, resume, trained_on,
// progress): the learner started fresh with its input normalisation fitted on `train`, or with options.resume from
// its checkpoint (default folder: out_path + ".ckpt"), then the epochs. before_loop(learner, start_epoch, &best_val)
// runs in between (InterRM: the untrained module's validation loss as the bar to beat). Sets the report's losses,
// epochs, best_val_loss and seconds (of the epochs).
template <typename Learner, typename Sample, typename Options, typename Report>
void trainRelationModule(const std::string& name, const Options& options, int batch_size,
                         const std::vector<Sample>& train, const std::vector<Sample>& val, Report* report,
                         const std::function<void(Learner&, int, double*)>& before_loop = {}) {
  if (options.out_path.empty()) throw std::runtime_error(name + " training: no output model path");
  const std::string ckpt = options.checkpoint_dir.empty() ? options.out_path + ".ckpt" : options.checkpoint_dir;
  Learner learner(options.config, options.config.train.seed);
  learner.setTrainedOn(options.trained_on);
  int start_epoch = 0;
  double best_val = std::numeric_limits<double>::infinity();
  if (options.resume && learner.loadCheckpoint(ckpt, &start_epoch, &best_val)) {
    RET3D_INFO(name << ": resuming from " << ckpt << " after epoch " << start_epoch);
    learner.setTrainedOn(options.trained_on);
  } else {
    learner.fitNormalisation(train);
  }
  if (before_loop) before_loop(learner, start_epoch, &best_val);
  const auto t0 = std::chrono::steady_clock::now();
  EpochLoopSettings loop;
  loop.name = name;
  loop.start_epoch = start_epoch;
  loop.epochs = options.config.train.epochs;
  loop.seed = options.config.train.seed;
  loop.batch_size = static_cast<std::size_t>(batch_size);
  loop.out_path = options.out_path;
  loop.checkpoint = ckpt;
  loop.progress = options.progress;
  using Loss = decltype(learner.evaluate(val));
  runEpochs<Learner, Sample, Loss>(loop, learner, train, val, &best_val, report);
  report->best_val_loss = best_val;
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace train
}  // namespace ret3d
