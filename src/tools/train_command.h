// `ret3d train <what>`: each learned stage adds its sub-subcommand from its own file, the same way subcommands
// register with `ret3d` (tools/command.h):
//
//   static ret3d::tools::TrainRegistrar reg("detector", "the LWD-3D base detector", [](CLI::App& app) {
//     ... app.add_option(...); return [=]() -> int { ...; return 0; };
//   });
#pragma once

#include <array>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "ret3d/io/detection_cache.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {

std::vector<CommandInfo>& trainRegistry();

struct TrainRegistrar {
  TrainRegistrar(std::string name, std::string description, CommandSetup setup) {
    trainRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

// `ret3d train <name>` of a relation module: Args (a RelationTrainArgs) gets the shared options with the help texts
// of --data, --detections and --config, then the module's own (extra, optional); run gets it with the command line.
template <class Args>
TrainRegistrar relationTrainer(const std::string& name, const std::string& description,
                               const std::array<std::string, 3>& help, int (*run)(const Args&),
                               void (*extra)(CLI::App&, Args&) = nullptr) {
  return TrainRegistrar(name, description, [=](CLI::App& app) -> CommandRun {
    auto a = std::make_shared<Args>();
    a->addOptions(app, help[0], help[1], help[2]);
    if (extra) extra(app, *a);
    return [a, &app, name, run]() {
      a->command_line = commandLine("ret3d train " + name, app);
      return run(*a);
    };
  });
}

// The relation modules' training input from this package's detector (--detector MODEL): its boxes and features on
// the scans of a KITTI tracking folder, computed once and cached (train/detector_outputs.h).
struct DetectorSource {
  std::string model, cache;
  double score_threshold = -1;
  void addOptions(CLI::App& app);
  bool given() const { return !model.empty(); }
  // `sequences` in the --sequences syntax ("" = all); the cache file is <cache or default_cache><suffix>.
  io::SequenceDetections run(const std::string& data, const std::string& sequences, int threads,
                             const std::string& default_cache, const std::string& suffix) const;
};

// What `ret3d train intra` and `ret3d train inter` share: the data and the boxes to refine (another detector's
// results or this package's detector), the output and checkpoint, the schedule, and --inspect.
struct RelationTrainArgs {
  std::string data, detections, out, config, sequences, val_sequences, checkpoint, inspect;
  DetectorSource detector;
  int epochs = -1, threads = 2;
  bool resume = false, quiet = false;
  std::string command_line;  // stored in the model file

  // The help of --data, --detections and --config names what the module reads.
  void addOptions(CLI::App& app, const std::string& data_help, const std::string& detections_help,
                  const std::string& config_help);
  // Throws std::runtime_error unless --data and --out are given with exactly one source of boxes.
  void validate() const;

  // The closing lines of a training run: epochs, time, losses, the model file. A Report has epochs_run, seconds,
  // first_train_loss, last_train_loss, best_val_loss and best_epoch; input_val_loss >= 0 is the validation loss of the
  // boxes as they came in.
  template <class Report>
  void printSummary(const std::string& what, const Report& r, bool validated, double input_val_loss = -1) const {
    std::cout << what << " trained: " << r.epochs_run << " epochs in " << r.seconds << " s; train loss "
              << r.first_train_loss << " -> " << r.last_train_loss;
    if (validated && input_val_loss >= 0)
      std::cout << "; validation loss " << input_val_loss << " (input boxes) -> best " << r.best_val_loss;
    else if (validated)
      std::cout << "; best validation loss " << r.best_val_loss;
    if (validated) std::cout << " (epoch " << r.best_epoch << ")";
    std::cout << "\nmodel: " << out << std::endl;
  }

  // --inspect: prints a relation model file's metadata (`what`: "IntraRM", "InterRM"); Info has format_version,
  // trained_on and a config that its namespace's toYaml prints.
  template <class Info>
  int printModelInfo(const std::string& what, const Info& info) const {
    std::cout << what << " model " << inspect << "\nformat_version: " << info.format_version
              << "\ntrained_on: " << info.trained_on << "\n"
              << toYaml(info.config) << std::endl;  // found by ADL in the module's namespace
    return 0;
  }

  // The trainer's options from these arguments: the module's config (`load` reads --config; default config
  // without it), --epochs, output, checkpoint, resume, progress and the command line for the model file.
  template <class Options, class LoadConfig>
  Options trainOptions(LoadConfig load) const {
    Options opt;
    opt.config = config.empty() ? decltype(opt.config){} : load(config);
    if (epochs >= 0) opt.config.train.epochs = epochs;
    opt.out_path = out;
    opt.checkpoint_dir = checkpoint;
    opt.resume = resume;
    opt.progress = !quiet;
    opt.trained_on = command_line;
    return opt;
  }
};

}  // namespace tools
}  // namespace ret3d
