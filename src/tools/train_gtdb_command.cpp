// `ret3d train gtdb --data DIR... --out FILE`: the ground-truth database for train.gt_database (SECOND-style
// ground-truth sampling): every labelled object of the model's classes in the training folders, with its returns.
#include <filesystem>
#include <iostream>
#include <map>
#include <stdexcept>

#include "ret3d/train/augmentations.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

CommandRun setup(CLI::App& app) {
  auto dirs = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  auto config = std::make_shared<std::string>();
  auto opt = std::make_shared<GtDatabaseOptions>();
  app.add_option("--data", *dirs, "KITTI tracking-layout training folder(s); never validation data")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--out", *out, "database file to write (e.g. data/gtdb/sim.gtdb)")->required();
  app.add_option("--config", *config, "detector config YAML: its model.classes (default Car, Pedestrian, Cyclist)")
      ->check(CLI::ExistingFile);
  app.add_option("--min-points", opt->min_points, "objects with fewer returns are left out")->capture_default_str();
  return [dirs, out, config, opt]() -> int {
    // The KITTI object frames are the project's real validation set: objects are never cut from them.
    for (const std::string& d : *dirs)
      for (const auto& part : std::filesystem::weakly_canonical(d))
        if (part == "kitti_object")
          throw std::runtime_error(d + ": the KITTI object frames are the validation set; never cut objects from them");
    const ModelConfig model = config->empty() ? ModelConfig() : loadDetectorOptions(*config).model;
    const DetectorDataset data(*dirs, model);
    const std::vector<GtObject> db = buildGtDatabase(data, *opt);
    const std::filesystem::path parent = std::filesystem::path(*out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    writeGtDatabase(*out, db);
    std::map<std::string, int> per_class;
    for (const GtObject& g : db) ++per_class[className(g.box.label)];
    std::cout << *out << ": " << db.size() << " objects from " << data.size() << " frames";
    for (const auto& [name, n] : per_class) std::cout << ", " << name << " " << n;
    std::cout << std::endl;
    return 0;
  };
}

TrainRegistrar reg("gtdb", "the ground-truth database for train.gt_database (objects cut from training folders)",
                   setup);

}  // namespace
}  // namespace tools
}  // namespace ret3d
