// `ret3d convert DATASET_DIR OUT.bag [--sequence SSSS] [--rate 10]`: KITTI-layout data to a bag.
// `ret3d convert --check BAG`: validates a bag and prints a summary; exit code 0 when valid, 1 otherwise.
#include <iostream>
#include <memory>
#include <optional>

#include "ret3d/core/progress.h"
#include "ret3d/ros/kitti_bag.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {
namespace {

struct ConvertArgs {
  std::string dataset_dir;
  std::string out_bag;
  std::string check_bag;
  ConvertOptions options;
};

int runCheck(const ConvertArgs& args) {
  const CheckReport report = checkBag(args.check_bag, args.options.fixed_frame);
  std::cout << report.summary() << std::flush;
  return report.ok() ? 0 : 1;
}

int runConvert(ConvertArgs args) {
  if (args.dataset_dir.empty() || args.out_bag.empty()) {
    std::cerr << "ret3d convert: give DATASET_DIR and OUT.bag, or --check BAG (see --help)" << std::endl;
    return 2;
  }
  std::optional<ProgressBar> bar;
  args.options.progress = [&bar](std::size_t done, std::size_t total) {
    if (!bar) bar.emplace("convert", total);
    bar->tick();
    if (done == total) bar->finish();
  };
  const std::size_t frames = convertKittiToBag(args.dataset_dir, args.out_bag, args.options);
  std::cout << "wrote " << frames << " frames to " << args.out_bag << std::endl;
  return 0;
}

CommandRegistrar registrar(
    "convert", "KITTI data (tracking sequence, object layout or a folder of .bin scans) to a bag; --check BAG",
    [](CLI::App& app) -> CommandRun {
      auto args = std::make_shared<ConvertArgs>();
      ConvertOptions& o = args->options;
      app.footer(
          "The bag holds /points (PointCloud2, velodyne driver layout), /tf (fixed -> base per frame, from the "
          "sequence's poses), /tf_static (base -> sensor) and, with labels, /ground_truth/objects (Object3DArray of "
          "Car, Pedestrian and Cyclist). Frame f is stamped START + f / RATE.");
      auto* dataset = app.add_option("DATASET_DIR", args->dataset_dir,
                                     "KITTI tracking or object layout ([training/]velodyne/...), or a folder of "
                                     "NNNNNN.bin scans")
                          ->check(CLI::ExistingDirectory);
      auto* out = app.add_option("OUT_BAG", args->out_bag, "bag to write (overwritten)");
      app.add_option("--check", args->check_bag,
                     "validate BAG (topics and types, monotonic stamps, a transform to the fixed frame at every "
                     "cloud, point fields) instead of converting; exit code 1 when it has problems")
          ->check(CLI::ExistingFile)
          ->excludes(dataset)
          ->excludes(out);
      app.add_option("--sequence", o.sequence, "tracking layout: sequence SSSS (default: the first with scans)");
      app.add_option("--rate", o.rate, "frame rate in Hz: frame f is stamped START + f / RATE")
          ->capture_default_str()
          ->check(CLI::PositiveNumber);
      app.add_option("--fixed-frame", o.fixed_frame,
                     "fixed (odometry) frame; with --check, the frame every cloud "
                     "must transform to")
          ->capture_default_str();
      app.add_option("--base-frame", o.base_frame, "vehicle frame")->capture_default_str();
      app.add_option("--sensor-frame", o.sensor_frame, "LiDAR frame (the clouds' frame_id)")->capture_default_str();
      app.add_option("--sensor-height", o.sensor_height, "LiDAR height above the base frame, m")->capture_default_str();
      app.add_option("--start-time", o.start_time, "stamp of frame 0, s")->capture_default_str();
      return [args]() -> int { return args->check_bag.empty() ? runConvert(*args) : runCheck(*args); };
    });

}  // namespace
}  // namespace tools
}  // namespace ret3d
