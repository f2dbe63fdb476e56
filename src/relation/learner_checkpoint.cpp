// Training checkpoints of the relation modules' learners (learner_checkpoint.h).
#include "learner_checkpoint.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

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
    const YAML::Node s = YAML::LoadFile(dir + "/state.yaml");
    *epoch = s["epoch"].as<int>();
    *best_val = s["best_val"].as<double>();
    std::istringstream r(s["rng"].as<std::string>());
    r >> *rng;
  } catch (const YAML::Exception& e) {
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
