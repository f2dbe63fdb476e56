// The evaluation report: metrics.json (flat keys, percent 0-100 except counts), report.md (tables a person reads:
// inputs, thresholds, counts, results) and PNG precision-recall plots drawn by gnuplot.
//
// metrics.json keys (read by other tools; exactly these names):
//   kitti.<Class>.<3d|bev|2d|aos>.<R11|R40>.<easy|moderate|hard>     strict IoU 0.7 / 0.5 / 0.5
//   kitti.false_boxes_per_frame[.<Class>|.score50], kitti.exact_recall (1 with --kitti-recall exact)
//   waymo.<Class|mean>.<L1|L2>.<AP|APH>
//   mot.<Class>.<MOTA|MOTP|IDSW|FRAG|MT|ML|HOTA|DetA|AssA>            IDSW, FRAG: counts; MT, ML: % of GT tracks
//   mot.<Class|all>.<IdStability|IdCoverage>                          eval/id_stability.h (centre distance < 2 m)
// and, under other prefixes: kitti_loose.* (IoU 0.5 / 0.25 / 0.25, same layout as kitti.*), waymo_range.<Class>.
// <0-30|30-50|50+>.<L1|L2>.<AP|APH>, mot_detail.<Class>.<...> (TP, FP, FN, PT, GT tracks, DetRe, DetPr, AssRe,
// AssPr, LocA), count.* (frames, objects, ground truth per difficulty), min_points.threshold and
// min_points.<Class>.<kept|ignored> (with --min-points: labels per class holding at least / fewer than that many
// returns). With --min-points, label_returns.csv beside them lists every label's returns.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "ret3d/eval/eval_data.h"
#include "ret3d/eval/id_stability.h"
#include "ret3d/eval/kitti_ap.h"
#include "ret3d/eval/mot_metrics.h"
#include "ret3d/eval/waymo_ap.h"

namespace ret3d {
namespace eval {

struct EvalReport {
  std::string gt_source, pred_source;  // descriptions of what was read
  std::size_t num_frames = 0, num_gt = 0, num_pred = 0;
  std::vector<std::string> notes;  // conversions and choices worth stating (e.g. bag -> camera labels)
  double seconds = 0;              // evaluation time

  const KittiResult* kitti = nullptr;
  const KittiResult* kitti_loose = nullptr;
  const WaymoResult* waymo = nullptr;
  WaymoOptions waymo_options;
  const MotResult* mot = nullptr;
  MotOptions mot_options;
  const IdStabilityResult* id_stability = nullptr;  // with the tracking metrics
  IdStabilityOptions id_stability_options;

  // --min-points (0: off): labels with fewer returns are ignored by every metric; per class, and every label.
  int min_points = 0;
  std::map<ObjectClass, MinPointsCounts> min_points_counts;
  std::vector<LabelReturns> label_returns;
};

// All numbers of the report under their metrics.json keys (sorted).
std::map<std::string, double> metricsMap(const EvalReport& report);
// The short table printed on stdout: moderate KITTI AP (3D/BEV R40), Waymo L1/L2 APH, MOTA/HOTA.
std::string headlineTable(const EvalReport& report);
// Writes DIR/metrics.json, DIR/report.md, DIR/label_returns.csv (with --min-points) and DIR/plots/*.png (plots
// skipped, with a warning, when gnuplot is missing). Creates DIR. Returns the PNG files written.
std::vector<std::string> writeReport(const std::string& dir, const EvalReport& report);

// Runs `gnuplot script` as a subprocess (no shell); true on success.
bool runGnuplot(const std::string& script_path);

}  // namespace eval
}  // namespace ret3d
