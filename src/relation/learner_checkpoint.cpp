// Training checkpoints of the relation modules' learners (learner_checkpoint.h).
#include "learner_checkpoint.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/yaml_reader.h"

namespace ret3d {
namespace relation {

namespace fs = std::filesystem;

void writeLearnerCheckpoint(const std::string& dir, const torch::optim::Optimizer& optimizer, int epoch,
                            double best_val, const std::mt19937_64& rng) {
  fs::create_directories(dir);
  torch::save(optimizer, dir + "/optimizer.pt");
  YAML::Node s;
  s["epoch"] = epoch;
  s["best_val"] = best_val;
  std::ostringstream r;
  r << rng;
  s["rng"] = r.str();
  const std::string tmp = dir + "/state.yaml.tmp";
  {
    std::ofstream out(tmp);
    YAML::Emitter e;
    e << s;
    out << e.c_str() << "\n";
  }
  fs::rename(tmp, dir + "/state.yaml");
}

bool readLearnerState(const std::string& dir, const std::string& module, int* epoch, double* best_val,
                      std::mt19937_64* rng) {
  if (!fs::exists(dir + "/state.yaml")) return false;
  try {
    // The one YAML reader: every key required, no other key, each of its type.
    YamlReader s = YamlReader::load(dir + "/state.yaml");
    std::string state;
    if (!s.get("epoch", epoch)) s.fail("epoch", "missing");
    if (!s.get("best_val", best_val)) s.fail("best_val", "missing");
    if (!s.get("rng", &state)) s.fail("rng", "missing");
    s.finish();
    std::istringstream r(state);
    r >> *rng;
    if (!r) s.fail("rng", "not a random generator state");
  } catch (const ConfigError& e) {
    throw std::runtime_error(module + " checkpoint " + dir + "/state.yaml: unreadable (" + std::string(e.what()) + ")");
  }
  return true;
}

void readLearnerOptimizer(const std::string& dir, const std::string& module, torch::optim::Optimizer* optimizer) {
  try {
    torch::load(*optimizer, dir + "/optimizer.pt");
  } catch (const std::exception& e) {
    const std::string msg = e.what();
    throw std::runtime_error(module + " checkpoint " + dir + "/optimizer.pt: unreadable (" +
                             msg.substr(0, msg.find('\n')) + ")");
  }
}

void copyWeights(const torch::nn::Module& from, const torch::nn::Module& to) {
  torch::NoGradGuard no_grad;
  auto dst_p = to.named_parameters();
  for (const auto& p : from.named_parameters()) dst_p[p.key()].copy_(p.value());
  auto dst_b = to.named_buffers();
  for (const auto& b : from.named_buffers()) dst_b[b.key()].copy_(b.value());
}

}  // namespace relation
}  // namespace ret3d
