// `ret3d bench-intra`: IntraRM's refine() time per frame for given object counts (target: 3 ms for 50 objects and
// 15 ms for 300 on 2 threads). Layouts are KITTI-like (objects spread over 70 m x 80 m in front of the sensor), plus
// a crowded one (all objects within 30 m x 30 m), so the graph's edge count is realistic and then pessimistic.
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>

#include "ret3d/relation/intra_rm.h"
#include "ret3d/relation/radius_graph.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {
namespace {

struct BenchIntraArgs {
  std::string model, counts = "50,300";
  int threads = 2, repeats = 200;
};

Detections layout(int n, double sx, double sy, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Detections d;
  for (int i = 0; i < n; ++i) {
    Box b;
    b.label = kDetectedClasses[static_cast<std::size_t>(i % 3)];
    b.length = b.label == ObjectClass::Car ? 3.9 : b.label == ObjectClass::Pedestrian ? 0.8 : 1.8;
    b.width = b.label == ObjectClass::Car ? 1.6 : 0.6;
    b.height = b.label == ObjectClass::Car ? 1.5 : 1.7;
    b.x = sx * u(rng);
    b.y = sy * (u(rng) - 0.5);
    b.z = -0.9;
    b.yaw = M_PI * (2 * u(rng) - 1);
    b.score = static_cast<float>(u(rng));
    d.boxes.push_back(b);
  }
  return d;
}

int runBenchIntra(const BenchIntraArgs& a) {
  relation::setTorchThreads(a.threads);
  std::unique_ptr<relation::IntraRM> m;
  if (a.model.empty()) {
    m = std::make_unique<relation::IntraRM>(relation::IntraRMArch{});
    std::cout << "untrained default-shape IntraRM (hidden 64, 4 rounds, r 2 m)\n";
  } else {
    relation::IntraRMOptions o;
    o.model_path = a.model;
    m = std::make_unique<relation::IntraRM>(o);
    std::cout << "IntraRM " << a.model << " (hidden " << m->arch().hidden << ", " << m->arch().rounds
              << " rounds, r " << m->arch().radius << " m)\n";
  }
  std::cout << "threads " << a.threads << ", " << a.repeats << " repeats, median ms per frame\n";
  std::mt19937 rng(1);
  std::stringstream ss(a.counts);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const int n = std::stoi(item);
    for (const bool crowded : {false, true}) {
      const Detections d = crowded ? layout(n, 30, 30, rng) : layout(n, 70, 80, rng);
      std::vector<Eigen::Vector2d> c;
      for (const Box& b : d.boxes) c.push_back({b.x, b.y});
      const std::size_t edges = relation::buildRadiusGraph(c, m->arch().radius, m->arch().use_edges).numEdges();
      for (int k = 0; k < 5; ++k) m->refine(d);  // warm-up
      std::vector<double> ms;
      for (int k = 0; k < a.repeats; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        m->refine(d);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      }
      std::sort(ms.begin(), ms.end());
      std::cout << std::setw(5) << n << " objects, " << (crowded ? "crowded 30x30 m" : "spread 70x80 m ")
                << ", " << std::setw(6) << edges << " edges: median " << std::fixed << std::setprecision(3)
                << ms[ms.size() / 2] << " ms, p90 " << ms[ms.size() * 9 / 10] << " ms\n";
    }
  }
  return 0;
}

CommandRegistrar reg("bench-intra", "time IntraRM refinement per frame", [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<BenchIntraArgs>();
  app.add_option("--model", a->model, "IntraRM model file (default: an untrained default-shape module)");
  app.add_option("--objects", a->counts, "comma-separated object counts")->capture_default_str();
  app.add_option("--threads", a->threads, "CPU threads for libtorch")->capture_default_str();
  app.add_option("--repeats", a->repeats, "timed runs per case")->capture_default_str();
  return [a]() { return runBenchIntra(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
