// `ret3d egomotion`: the ego motion from consecutive scans (core/scan_matching.h), by each registration side by side
// on the same scans, the way `ret3d autolabel` chains it (each match started from the previous motion):
//   ret3d egomotion --data data/simreg --matchers icp,gicp [--sequences 0-1] [--per-frame OUT.csv]
// With ego poses (pose/ or oxts/, e.g. a simulated drive's exact ones): per-frame translation and yaw error of the
// frame-to-frame motion, and the drift of the chained trajectory at the last frame. Without (a folder of scans): the
// agreement of each matcher with the first one. Always: time per frame (both scans' downsampling and the match), as
// wall-clock and as the process's CPU time (all threads), the fairer figure on a shared machine.
#include <time.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "ret3d/core/geometry.h"
#include "ret3d/core/scan_matching.h"
#include "ret3d/core/stats.h"
#include "ret3d/core/transform.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/io/kitti.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {
namespace {

struct EgomotionArgs {
  std::string data, sequences, matchers = "icp,gicp", per_frame;
  int frames = 0;  // 0: all
};

constexpr double kDeg = 180.0 / M_PI;

double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// One matcher's chained estimate over a sequence, and its per-frame figures.
struct Track {
  ScanMatchingOptions options;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity(), pose = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Isometry3d> motions;
  std::vector<double> ms, cpu_ms, trans_err, yaw_err;  // per frame (errors against the reference: truth or matcher 1)
  int failed = 0;
};

// Translation (m, in the plane) and yaw (deg) difference of two motions.
std::pair<double, double> difference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return {(a.translation() - b.translation()).head<2>().norm(), std::abs(wrapAngle(yawOf(a) - yawOf(b))) * kDeg};
}

std::string stats(const std::vector<double>& v, int precision) {
  double sum = 0;
  for (double x : v) sum += x;
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << (v.empty() ? 0.0 : sum / v.size()) << " / "
    << percentile(v, 95) << " / " << percentile(v, 100);
  return s.str();
}

void runSequence(const EgomotionArgs& a, const kitti::TrackingDataset& ds, const std::string& seq,
                 std::vector<Track> tracks, std::ostream* csv) {
  std::vector<int> frames = ds.frames(seq);
  if (a.frames > 0 && static_cast<int>(frames.size()) > a.frames) frames.resize(static_cast<std::size_t>(a.frames));
  if (frames.size() < 2) throw std::runtime_error("sequence " + seq + ": fewer than 2 scans in " + a.data);
  const std::vector<Eigen::Isometry3d> truth = ds.lidarPoses(seq);
  const bool have_truth = !truth.empty();
  PointCloud previous = kitti::readVelodyne(ds.velodynePath(seq, frames[0]));
  for (std::size_t k = 1; k < frames.size(); ++k) {
    PointCloud cloud = kitti::readVelodyne(ds.velodynePath(seq, frames[k]));
    Eigen::Isometry3d reference = Eigen::Isometry3d::Identity();
    if (have_truth) reference = truth.at(frames[k - 1]).inverse() * truth.at(frames[k]);
    for (std::size_t m = 0; m < tracks.size(); ++m) {
      Track& t = tracks[m];
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpuSeconds();
      const ScanMatch match = matchScans(cloud, previous, t.motion, t.options);
      t.cpu_ms.push_back(1e3 * (cpuSeconds() - c0));
      t.ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (match.converged) t.motion = match.source_to_target;
      else ++t.failed;
      t.pose = t.pose * t.motion;
      t.motions.push_back(t.motion);
      const auto [dt, dyaw] = difference(t.motion, have_truth ? reference : tracks[0].motions.back());
      t.trans_err.push_back(dt), t.yaw_err.push_back(dyaw);
      if (csv)
        *csv << seq << "," << frames[k] << "," << scanMatcherName(t.options.matcher) << "," << t.ms.back() << ","
             << t.cpu_ms.back() << "," << dt << "," << dyaw << "," << (match.converged ? 1 : 0) << "\n";
    }
    previous = std::move(cloud);
  }
  const Eigen::Isometry3d truth_end =
      have_truth ? truth.at(frames.front()).inverse() * truth.at(frames.back()) : tracks[0].pose;
  const double travelled = truth_end.translation().head<2>().norm();
  std::cout << "sequence " << seq << ": " << frames.size() << " scans, " << std::fixed << std::setprecision(1)
            << travelled << " m " << (have_truth ? "driven (ego poses)" : "by the first matcher")
            << "; errors against " << (have_truth ? "the ego poses" : scanMatcherName(tracks[0].options.matcher))
            << " (mean / p95 / max)\n";
  for (const Track& t : tracks) {
    const auto [drift, drift_yaw] = difference(t.pose, truth_end);
    std::cout << "  " << std::setw(5) << scanMatcherName(t.options.matcher) << ": per frame translation "
              << stats(t.trans_err, 3) << " m, yaw " << stats(t.yaw_err, 3) << " deg; after " << frames.size() - 1
              << " frames " << std::setprecision(2) << drift << " m (" << std::setprecision(2)
              << (travelled > 0 ? 100.0 * drift / travelled : 0.0) << " %), " << drift_yaw << " deg; "
              << t.failed << " failed; time per frame: CPU " << stats(t.cpu_ms, 0) << " ms, wall " << stats(t.ms, 0)
              << " ms\n";
  }
  std::cout << std::defaultfloat << std::flush;
}

int runEgomotion(const EgomotionArgs& a) {
  std::vector<Track> tracks;
  std::stringstream list(a.matchers);
  for (std::string name; std::getline(list, name, ',');) {
    Track t;
    t.options.matcher = parseScanMatcher(name);
    tracks.push_back(t);
  }
  if (tracks.empty()) throw std::runtime_error("--matchers: none given (icp, gicp)");
  kitti::TrackingDataset ds(a.data);
  const std::vector<std::string> seqs = a.sequences.empty() ? ds.sequences() : eval::parseSequenceList(a.sequences);
  std::unique_ptr<std::ofstream> csv;
  if (!a.per_frame.empty()) {
    csv = std::make_unique<std::ofstream>(a.per_frame);
    if (!*csv) throw std::runtime_error("cannot write " + a.per_frame);
    *csv << "sequence,frame,matcher,wall_ms,cpu_ms,translation_error_m,yaw_error_deg,converged\n";
  }
  for (const std::string& seq : seqs) runSequence(a, ds, seq, tracks, csv.get());
  return 0;
}

CommandRegistrar reg("egomotion", "ego motion from consecutive scans by each scan matcher, side by side: errors "
                     "against ego poses (or agreement), drift, time per frame",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<EgomotionArgs>();
  app.add_option("--data", a->data, "a KITTI tracking root (training/velodyne/SSSS/, pose/ or oxts/ for errors) or a "
                 "plain folder of consecutive FFFFFF.bin scans")->required();
  app.add_option("--sequences", a->sequences, "tracking sequences, e.g. 0-1 (default: all)");
  app.add_option("--matchers", a->matchers, "comma list of icp, gicp; the first is the reference without poses")
      ->capture_default_str();
  app.add_option("--frames", a->frames, "first N scans of each sequence (0: all)")->capture_default_str();
  app.add_option("--per-frame", a->per_frame, "CSV of every frame's time and errors");
  return [a]() { return runEgomotion(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
