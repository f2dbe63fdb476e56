// `ret3d train far-field --near MODEL --far MODEL --near-extent=X0,X1,Y0,Y1 [--margin M] --out DIR`: the
// two-resolution detector (inference.far_field) as one folder of models: DIR/detector.pt is the near model
// with its stored config extended by the near field (inference.grid_extent) and the far field, DIR/detector_far.pt the
// far model. Nothing is trained: both networks keep their weights. The folder then loads as any other
// (`--models DIR`, the nodelets' model_path) once intra_rm.pt and inter_rm.pt are beside it.
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "ret3d/detector/detector.h"
#include "ret3d/detector/model_file.h"
#include "tools/train_command.h"

namespace ret3d {
namespace tools {
namespace {

// The near model's config text with `inference:` given the near field and the far field. The keys are written into
// the text (its comments, which say how the model was made, are kept); a config that sets either already is refused.
std::string withFarField(const std::string& text, const std::string& origin, const GridExtent& near, double margin) {
  const InferenceOptions given = detectorOptionsFromYaml(text, origin).inference;
  if (given.grid_extent || given.far_field)
    throw std::runtime_error(origin + ": its config sets inference.grid_extent or inference.far_field already");
  std::ostringstream keys;
  keys << "  # the two-resolution detector (ret3d train far-field): this network over the near field, beside\n"
       << "  grid_extent: " << near.describe() << "\n"
       << "  far_field:\n"
       << "    model_path: detector_far.pt\n"
       << "    margin: " << margin << "\n";
  const std::string key = "\ninference:\n";
  const std::size_t at = ("\n" + text).find(key);
  if (at == std::string::npos) return text + (text.empty() || text.back() == '\n' ? "" : "\n") + "inference:\n" + keys.str();
  const std::size_t insert = at + key.size() - 1;  // in `text`: just after "inference:\n"
  return text.substr(0, insert) + keys.str() + text.substr(insert);
}

CommandRun setup(CLI::App& app) {
  auto near = std::make_shared<std::string>();
  auto far = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto extent = std::make_shared<std::vector<double>>();
  auto margin = std::make_shared<double>(FarFieldOptions().margin);
  app.add_option("--near", *near, "the near model (fine cells), e.g. models/lwd3d/detector.pt")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--far", *far, "the far model (coarse cells over the whole ground), e.g. trained with "
                                "config/detector/lwd3d_anchor_far.yaml")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--near-extent", *extent,
                 "the near field, x_min,x_max,y_min,y_max in m (e.g. --near-extent=-32,32,-32,32): the near model's "
                 "network runs there, the far model's boxes are taken outside it")
      ->required()
      ->expected(4)
      ->delimiter(',');
  app.add_option("--margin", *margin, "m: near boxes this close to the near field's edge yield to the far model's")
      ->capture_default_str();
  app.add_option("--out", *out, "folder to write detector.pt and detector_far.pt to")->required();
  return [near, far, out, extent, margin]() -> int {
    const ModelFileContents file = readModelFile(*near);
    if (file.metadata.trained_with.empty())
      throw std::runtime_error(*near + ": the file does not store the config it was trained with");
    const GridExtent e = GridExtent::fromValues(*extent);
    ModelMetadata m = file.metadata;
    m.trained_with = withFarField(m.trained_with, *near, e, *margin);
    DetectorOptions check = detectorOptionsFromYaml(m.trained_with, *near + " with the far field");
    check.model = m.config;
    check.validate();  // the near field in whole cells the network can run on

    std::filesystem::create_directories(*out);
    const std::string near_out = (std::filesystem::path(*out) / "detector.pt").string();
    const std::string far_out = (std::filesystem::path(*out) / "detector_far.pt").string();
    if (!std::filesystem::exists(far_out) || !std::filesystem::equivalent(*far, far_out))
      std::filesystem::copy_file(*far, far_out, std::filesystem::copy_options::overwrite_existing);
    writeModelFile(near_out, m, file.weights);
    const Detector detector(detectorOptionsForModel(near_out));  // loads both, as the pipeline will
    std::cout << near_out << ": " << detector.parameterCount() << " parameters; grid " << detector.describeGrids()
              << std::endl;
    return 0;
  };
}

TrainRegistrar reg("far-field",
                   "the two-resolution detector: a near model and a far model as one folder (nothing trained)", setup);

}  // namespace
}  // namespace tools
}  // namespace ret3d
