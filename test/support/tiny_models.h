// Real but untrained model files, small enough for a busy 2-core test machine: the default detector config on a
// 96 x 96 cell grid (48 m at 0.5 m: the same network, a quarter of the work) and the relation modules at small
// widths, saved with the stages' own save functions, so the nodelets and the command line load them as they load
// trained ones. For the tests that run the pipeline (bench_command_test; the rostests build the same by hand).
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "ret3d/detector/detector.h"
#include "ret3d/detector/nn/model.h"
#include "ret3d/relation/inter_rm.h"
#include "ret3d/relation/intra_rm.h"

namespace ret3d {
namespace test {

// config/detector/lwd3d_center.yaml (under source_dir) on the small grid; throws when the file has changed so much
// that a replaced line is missing.
inline std::string smallDetectorConfig(const std::string& source_dir) {
  std::ifstream in(source_dir + "/config/detector/lwd3d_center.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{{"x_min: -48.0", "x_min: -24.0"},
                                                                                {"x_max: 48.0", "x_max: 24.0"},
                                                                                {"y_min: -48.0", "y_min: -24.0"},
                                                                                {"y_max: 48.0", "y_max: 24.0"},
                                                                                {"resolution: 0.25", "resolution: 0.5"}}) {
    const auto pos = text.find(from);
    if (pos == std::string::npos) throw std::runtime_error("lwd3d_center.yaml: no line '" + from + "'");
    text.replace(pos, from.size(), to);
  }
  return text;
}

// Writes dir/detector.yaml (the small grid), dir/detector.pt, dir/intra_rm.pt and dir/inter_rm.pt: a --models folder.
inline void writeTinyModels(const std::string& dir, const std::string& source_dir) {
  std::ofstream(dir + "/detector.yaml") << smallDetectorConfig(source_dir);
  DetectorOptions options = loadDetectorOptions(dir + "/detector.yaml");
  options.inference.threads = 1;
  Detector(options).model().save(dir + "/detector.pt");
  relation::IntraRM(relation::IntraRMArch{}, 1).save(dir + "/intra_rm.pt");
  relation::InterRMArch inter;
  inter.c_enc = 64;
  inter.heads = 4;
  relation::InterRM(inter, 1).save(dir + "/inter_rm.pt");
}

}  // namespace test
}  // namespace ret3d
