#include "ret3d/eval/report.h"

#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/json_writer.h"
#include "ret3d/core/log.h"

extern char** environ;

namespace ret3d {
namespace eval {

namespace fs = std::filesystem;

namespace {

const char* const kAos = "aos";

std::string fmt(double v, int decimals = 2) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void addKitti(std::map<std::string, double>& m, const std::string& prefix, const KittiResult& r) {
  for (const auto& c : r.classes) {
    const std::string cls = className(c.cls);
    for (int d = 0; d < kKittiNumDifficulties; ++d) {
      const std::string diff = difficultyKey(static_cast<KittiDifficulty>(d));
      for (int mi = 0; mi < kKittiNumMetrics; ++mi) {
        const std::string base = prefix + "." + cls + "." + metricKey(static_cast<KittiMetric>(mi));
        m[base + ".R11." + diff] = c.curves[mi][d].ap11();
        m[base + ".R40." + diff] = c.curves[mi][d].ap40();
      }
      if (r.aos_valid) {
        m[prefix + "." + cls + "." + kAos + ".R11." + diff] = c.aos[d].ap11();
        m[prefix + "." + cls + "." + kAos + ".R40." + diff] = c.aos[d].ap40();
      }
    }
  }
}

const KittiCurve& kittiCurve(const KittiClassResult& c, int metric_or_aos, int d) {
  return metric_or_aos < kKittiNumMetrics ? c.curves[metric_or_aos][d] : c.aos[d];
}

const char* kittiMetricTitle(int i) {
  static const char* const titles[] = {"2D", "BEV", "3D", "AOS"};
  return titles[i];
}

std::string pathJoin(const std::string& a, const std::string& b) { return (fs::path(a) / b).string(); }

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << text;
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::string safeName(std::string s) {
  for (char& ch : s) {
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  }
  return s;
}

// A gnuplot script for one PNG; `series` are (data file, using-columns, title).
struct Series {
  std::string data, columns, title;
};

bool plot(const std::string& dir, const std::string& name, const std::string& title, const std::string& ylabel,
          const std::vector<Series>& series) {
  std::ostringstream gp;
  gp << "set terminal pngcairo size 640,480 enhanced font 'DejaVu Sans,11'\n"
     << "set output '" << pathJoin(dir, name + ".png") << "'\n"
     << "set title \"" << title << "\" noenhanced\n"
     << "set xlabel 'Recall'\nset ylabel '" << ylabel << "'\n"
     << "set xrange [0:1]\nset yrange [0:1.05]\nset grid\nset key bottom left box opaque noenhanced\n"
     << "plot ";
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (i) gp << ", ";
    gp << "'" << pathJoin(dir, series[i].data) << "' using " << series[i].columns << " with lines lw 2 title \""
       << series[i].title << "\"";
  }
  gp << "\n";
  const std::string script = pathJoin(dir, name + ".gp");
  writeFile(script, gp.str());
  return runGnuplot(script);
}

}  // namespace

bool runGnuplot(const std::string& script_path) {
  std::string prog = "gnuplot";
  std::vector<char*> argv = {prog.data(), const_cast<char*>(script_path.c_str()), nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, "gnuplot", nullptr, nullptr, argv.data(), environ) != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

namespace {

// Frames, boxes, the min_points counts, and the KITTI per-class detection and ground-truth counts.
void addCounts(std::map<std::string, double>& m, const EvalReport& r) {
  m["count.frames"] = static_cast<double>(r.num_frames);
  m["count.gt"] = static_cast<double>(r.num_gt);
  m["count.pred"] = static_cast<double>(r.num_pred);
  if (r.min_points > 0) {
    m["min_points.threshold"] = r.min_points;
    for (const auto& [cls, c] : r.min_points_counts) {
      m[std::string("min_points.") + className(cls) + ".kept"] = static_cast<double>(c.kept);
      m[std::string("min_points.") + className(cls) + ".ignored"] = static_cast<double>(c.ignored);
    }
  }
}

// KITTI AP, its counts and the false boxes per frame.
void addKittiMetrics(std::map<std::string, double>& m, const KittiResult& k) {
  addKitti(m, "kitti", k);
  for (const auto& c : k.classes) {
    const std::string cls = className(c.cls);
    m["count.kitti." + cls + ".det"] = c.num_det;
    for (int d = 0; d < kKittiNumDifficulties; ++d) {
      m["count.kitti." + cls + ".gt." + difficultyKey(static_cast<KittiDifficulty>(d))] = c.curves[2][d].num_gt;
    }
  }
  const KittiFalseBoxes& fb = k.false_boxes;
  const double nf = static_cast<double>(std::max<std::size_t>(1, k.num_frames));
  m["kitti.false_boxes_per_frame"] = fb.total() / nf;
  m["kitti.false_boxes_per_frame.score50"] = fb.totalScore50() / nf;
  for (const auto& c : k.classes) {
    const std::size_t i = static_cast<std::size_t>(c.cls) - 1;
    m[std::string("kitti.false_boxes_per_frame.") + className(c.cls)] = fb.per_class[i] / nf;
  }
  m["kitti.exact_recall"] = k.exact_recall ? 1 : 0;
}

// Waymo AP / APH per class and level, per range bin, and their means.
void addWaymo(std::map<std::string, double>& m, const WaymoResult& w, const WaymoOptions& options) {
  for (int l = 0; l < kWaymoNumLevels; ++l) {
    const std::string level = levelKey(static_cast<WaymoLevel>(l));
    for (const auto& c : w.classes) {
      const std::string cls = className(c.cls);
      m["waymo." + cls + "." + level + ".AP"] = c.levels[l].ap;
      m["waymo." + cls + "." + level + ".APH"] = c.levels[l].aph;
      m["count.waymo." + cls + "." + level + ".gt"] = c.levels[l].num_gt;
      for (std::size_t k = 0; k < c.ranges.size() && k < options.ranges.size(); ++k) {
        const std::string base = "waymo_range." + cls + "." + options.ranges[k].name + "." + level;
        m[base + ".AP"] = c.ranges[k][l].ap;
        m[base + ".APH"] = c.ranges[k][l].aph;
      }
    }
    m["waymo.mean." + level + ".AP"] = w.mean_ap[l];
    m["waymo.mean." + level + ".APH"] = w.mean_aph[l];
  }
}

// CLEAR MOT and HOTA per class (headline figures under mot., the rest under mot_detail.).
void addMot(std::map<std::string, double>& m, const MotResult& mot, const MotOptions& options) {
  m["mot_detail.max_range"] = options.max_range;
  for (const auto& c : mot.classes) {
    const std::string p = "mot." + std::string(className(c.cls)) + ".";
    const double tracks = std::max(1, c.clear.num_gt_tracks);
    m[p + "MOTA"] = c.clear.mota;
    m[p + "MOTP"] = c.clear.motp;
    m[p + "IDSW"] = c.clear.idsw;
    m[p + "FRAG"] = c.clear.frag;
    m[p + "MT"] = 100.0 * c.clear.mt / tracks;
    m[p + "ML"] = 100.0 * c.clear.ml / tracks;
    m[p + "HOTA"] = c.hota.hota;
    m[p + "DetA"] = c.hota.deta;
    m[p + "AssA"] = c.hota.assa;
    const std::string q = "mot_detail." + std::string(className(c.cls)) + ".";
    m[q + "TP"] = c.clear.tp;
    m[q + "FP"] = c.clear.fp;
    m[q + "FN"] = c.clear.fn;
    m[q + "PT"] = 100.0 * c.clear.pt / tracks;
    m[q + "GT_tracks"] = c.clear.num_gt_tracks;
    m[q + "pred_tracks"] = c.num_pred_tracks;
    m[q + "DetRe"] = c.hota.detre;
    m[q + "DetPr"] = c.hota.detpr;
    m[q + "AssRe"] = c.hota.assre;
    m[q + "AssPr"] = c.hota.asspr;
    m[q + "LocA"] = c.hota.loca;
  }
}

}  // namespace

std::map<std::string, double> metricsMap(const EvalReport& r) {
  std::map<std::string, double> m;
  addCounts(m, r);
  if (r.kitti) addKittiMetrics(m, *r.kitti);
  if (r.kitti_loose) addKitti(m, "kitti_loose", *r.kitti_loose);
  if (r.waymo) addWaymo(m, *r.waymo, r.waymo_options);
  if (r.mot) addMot(m, *r.mot, r.mot_options);
  if (r.id_stability) {
    auto add = [&m](const std::string& name, const IdStabilityCounts& c) {
      m["mot." + name + ".IdStability"] = c.stability();
      m["mot." + name + ".IdCoverage"] = c.coverage();
    };
    for (const auto& c : r.id_stability->classes) add(className(c.cls), c.counts);
    add("all", r.id_stability->all);
  }
  return m;
}

std::string headlineTable(const EvalReport& r) {
  std::ostringstream o;
  char line[256];
  if (r.kitti) {
    o << "KITTI AP (" << (r.kitti->exact_recall ? "exact recall sampling" : "devkit")
      << ", R40; R11 in brackets)  easy / moderate / hard\n";
    for (const auto& c : r.kitti->classes) {
      for (int mi : {2, 1, 0}) {
        const auto& cv = c.curves[mi];
        std::snprintf(line, sizeof line, "  %-10s %-3s @%.2f  %6.2f / %6.2f / %6.2f   [%6.2f / %6.2f / %6.2f]\n",
                      className(c.cls), kittiMetricTitle(mi), c.min_overlap, cv[0].ap40(), cv[1].ap40(),
                      cv[2].ap40(), cv[0].ap11(), cv[1].ap11(), cv[2].ap11());
        o << line;
      }
    }
    const KittiFalseBoxes& fb = r.kitti->false_boxes;
    const double nf = std::max<std::size_t>(1, r.kitti->num_frames);
    std::snprintf(line, sizeof line,
                  "  false boxes per frame (on no label, not in DontCare): %.2f (Car %.2f, Pedestrian %.2f, Cyclist "
                  "%.2f); score >= 0.5: %.2f\n",
                  fb.total() / nf, fb.per_class[0] / nf, fb.per_class[1] / nf, fb.per_class[2] / nf,
                  fb.totalScore50() / nf);
    o << line;
  }
  if (r.waymo) {
    o << "Waymo-style (3D IoU, 360 deg)            L1 AP / APH      L2 AP / APH\n";
    for (const auto& c : r.waymo->classes) {
      std::snprintf(line, sizeof line, "  %-10s @%.2f                    %6.2f / %6.2f   %6.2f / %6.2f\n",
                    className(c.cls), c.iou_threshold, c.levels[0].ap, c.levels[0].aph, c.levels[1].ap,
                    c.levels[1].aph);
      o << line;
    }
    std::snprintf(line, sizeof line, "  %-10s                          %6.2f / %6.2f   %6.2f / %6.2f\n", "mean",
                  r.waymo->mean_ap[0], r.waymo->mean_aph[0], r.waymo->mean_ap[1], r.waymo->mean_aph[1]);
    o << line;
  }
  if (r.mot) {
    o << "Tracking (" << similarityName(r.mot_options.similarity) << " >= " << r.mot_options.threshold;
    if (r.mot_options.max_range > 0) o << ", within " << r.mot_options.max_range << " m";
    o << ")   MOTA    MOTP   IDSW   FRAG    HOTA    DetA    AssA\n";
    for (const auto& c : r.mot->classes) {
      std::snprintf(line, sizeof line, "  %-10s          %7.2f %7.2f %6d %6d %7.2f %7.2f %7.2f\n", className(c.cls),
                    c.clear.mota, c.clear.motp, c.clear.idsw, c.clear.frag, c.hota.hota, c.hota.deta, c.hota.assa);
      o << line;
    }
  }
  return o.str();
}

namespace {

std::string metricsJson(const std::map<std::string, double>& m) {
  JsonWriter json({/*decimals=*/4, /*whole_as_integer=*/true, /*top_level_lines=*/true});
  for (const auto& [k, v] : m) json.field(k, v);
  return json.str();
}

void kittiTable(std::ostringstream& md, const KittiResult& k, const std::vector<std::string>& pngs,
                const std::string& plot_prefix) {
  md << "| class | metric | IoU | R11 easy | R11 moderate | R11 hard | R40 easy | R40 moderate | R40 hard |\n"
     << "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const auto& c : k.classes) {
    for (int mi : {2, 1, 0, 3}) {
      if (mi == 3 && !k.aos_valid) continue;
      md << "| " << className(c.cls) << " | " << kittiMetricTitle(mi) << " | " << fmt(c.min_overlap) << " |";
      for (int d = 0; d < 3; ++d) md << " " << fmt(kittiCurve(c, mi, d).ap11()) << " |";
      for (int d = 0; d < 3; ++d) md << " " << fmt(kittiCurve(c, mi, d).ap40()) << " |";
      md << "\n";
    }
  }
  md << "\n";
  if (!plot_prefix.empty()) {
    for (const auto& png : pngs) {
      if (png.rfind(plot_prefix, 0) == 0) md << "![" << png << "](plots/" << png << ")\n";
    }
    md << "\n";
  }
}

// Draws the plots with gnuplot into one folder; after the first failure (gnuplot missing) it stops trying.
class Plots {
 public:
  explicit Plots(std::string dir) : dir_(std::move(dir)) {}
  const std::string& dir() const { return dir_; }
  const std::vector<std::string>& pngs() const { return pngs_; }
  void draw(const std::string& name, const std::string& title, const std::string& ylabel,
            const std::vector<Series>& series) {
    if (!gnuplot_ok_) return;
    if (plot(dir_, name, title, ylabel, series)) {
      pngs_.push_back(name + ".png");
    } else {
      gnuplot_ok_ = false;
      RET3D_WARN("gnuplot failed or is missing: no plots (metrics.json and report.md are complete)");
    }
  }

 private:
  std::string dir_;
  std::vector<std::string> pngs_;
  bool gnuplot_ok_ = true;
};

// Precision-recall curves per class, metric and difficulty (data beside each plot).
void plotKitti(const EvalReport& r, Plots* plots) {
  for (const auto& c : r.kitti->classes) {
    for (int mi = 0; mi < 4; ++mi) {
      if (mi == 3 && !r.kitti->aos_valid) continue;
      const std::string name = std::string("kitti_") + className(c.cls) + "_" + safeName(kittiMetricTitle(mi));
      std::ostringstream data;
      data << "# recall easy moderate hard (devkit's 41 samples, interpolated)\n";
      for (int i = 0; i < kKittiSamplePoints; ++i) {
        data << fmt(i / 40.0, 3);
        for (int d = 0; d < 3; ++d) data << " " << fmt(kittiCurve(c, mi, d).precision[i], 6);
        data << "\n";
      }
      writeFile(pathJoin(plots->dir(), name + ".txt"), data.str());
      std::vector<Series> s;
      for (int d = 0; d < 3; ++d) {
        const auto& cv = kittiCurve(c, mi, d);
        const std::string label = std::string(d == 0 ? "Easy" : d == 1 ? "Moderate" : "Hard") + " (R40 " +
                                  fmt(cv.ap40()) + ", R11 " + fmt(cv.ap11()) + ", " + std::to_string(cv.num_gt) +
                                  " GT)";
        s.push_back({name + ".txt", "1:" + std::to_string(d + 2), label});
      }
      const std::string title = std::string("KITTI ") + className(c.cls) + " " + kittiMetricTitle(mi) +
                                (mi == 3 ? " (2D match" : " (IoU") + " >= " + fmt(c.min_overlap) + ")";
      plots->draw(name, title, mi == 3 ? "Orientation similarity" : "Precision", s);
    }
  }
}

// Precision-recall and heading-weighted curves per class and level.
void plotWaymo(const EvalReport& r, Plots* plots) {
  for (const auto& c : r.waymo->classes) {
    const std::string name = std::string("waymo_") + className(c.cls);
    std::vector<Series> s;
    for (int l = 0; l < kWaymoNumLevels; ++l) {
      const auto& cv = c.levels[l];
      const std::string data_name = name + "_" + levelKey(static_cast<WaymoLevel>(l)) + ".txt";
      std::ostringstream data;
      data << "# recall precision recall_h precision_h (one row per score cutoff)\n0 1 0 1\n";
      for (std::size_t i = 0; i < cv.recall.size(); ++i) {
        data << fmt(cv.recall[i], 6) << " " << fmt(cv.precision[i], 6) << " " << fmt(cv.recall_h[i], 6) << " "
             << fmt(cv.precision_h[i], 6) << "\n";
      }
      writeFile(pathJoin(plots->dir(), data_name), data.str());
      const std::string lv = levelKey(static_cast<WaymoLevel>(l));
      s.push_back({data_name, "1:2", lv + " AP " + fmt(cv.ap) + " (" + std::to_string(cv.num_gt) + " GT)"});
      s.push_back({data_name, "3:4", lv + " APH " + fmt(cv.aph)});
    }
    plots->draw(name, std::string("Waymo-style ") + className(c.cls) + " (3D IoU >= " + fmt(c.iou_threshold) + ")",
         "Precision", s);
  }
}

void reportInputs(std::ostringstream& md, const EvalReport& r) {
  md << "# ret3d evaluation report\n\n## Inputs\n\n"
     << "| | |\n| --- | --- |\n"
     << "| ground truth | " << r.gt_source << " |\n"
     << "| predictions | " << r.pred_source << " |\n"
     << "| frames | " << r.num_frames << " |\n"
     << "| ground-truth objects (all types, incl. DontCare) | " << r.num_gt << " |\n"
     << "| predictions | " << r.num_pred << " |\n"
     << "| evaluation time | " << fmt(r.seconds) << " s |\n\n";
  if (!r.notes.empty()) {
    md << "Notes:\n\n";
    for (const auto& n : r.notes) md << "- " << n << "\n";
    md << "\n";
  }
}

void reportMinPoints(std::ostringstream& md, const EvalReport& r) {
  md << "## Labels holding few returns (--min-points " << r.min_points << ")\n\n"
     << "Returns of a label: the points of its frame's scan inside its box grown by " << fmt(kLabelReturnMargin)
     << " m on every side. A label holding fewer than " << r.min_points
     << " is ignored by every metric, as the Waymo Open Dataset leaves out objects without enough returns: not a miss "
        "when unmatched, and a prediction matched to it neither a true nor a false positive. Every label's count: "
        "label_returns.csv.\n\n"
     << "| class | labels kept | labels ignored |\n| --- | ---: | ---: |\n";
  for (const auto& [cls, c] : r.min_points_counts)
    md << "| " << className(cls) << " | " << c.kept << " | " << c.ignored << " |\n";
  md << "\n";
}

std::string labelReturnsCsv(const std::vector<LabelReturns>& labels) {
  std::ostringstream csv;
  csv << "sequence,frame,label,type,track_id,range_m,returns,ignored\n";
  for (const LabelReturns& l : labels)
    csv << l.sequence << "," << l.frame << "," << l.label << "," << l.type << "," << l.track_id << "," << fmt(l.range)
        << "," << l.returns << "," << (l.ignored ? 1 : 0) << "\n";
  return csv.str();
}

void reportKitti(std::ostringstream& md, const EvalReport& r, const std::vector<std::string>& pngs) {
  md << "## KITTI object detection AP (official devkit rules)\n\n"
     << "Computed as the KITTI object devkit (evaluate_object_3d_offline, with the 2017 minimum-height fix) in "
        "camera coordinates. Difficulty: easy = 2D box height >= 40 px, occlusion 0, truncation <= 0.15; moderate "
        "= >= 25 px, occlusion <= 1, truncation <= 0.3; hard = >= 25 px, occlusion <= 2, truncation <= 0.5. "
        "Van is ignored for Car and Person_sitting for Pedestrian; detections in DontCare regions are not false "
        "positives; detections below the minimum height are ignored. R11 = the devkit's printed 11-point AP "
        "(mean precision at its sample points 0, 4, ..., 40 of 41); R40 = mean precision at recall 1/40 .. 40/40. AOS uses the 2D "
        "matching. Values in percent.\n\n"
     << (r.kitti->exact_recall
             ? "**Exact recall sampling** (`--kitti-recall exact`): the precision at recall k/40 is the best precision "
               "at an actual recall of at least k/40, every true positive's score a threshold. The devkit's own "
               "sampling takes its k-th threshold as recall k/40, which holds only with 40 or more valid ground "
               "truths per class and difficulty: with fewer, matching every object still scores (TP - 1) / 40.\n\n"
             : "")
     << "Ground truth counted (valid at each difficulty) and detections:\n\n"
     << "| class | easy | moderate | hard | detections |\n| --- | ---: | ---: | ---: | ---: |\n";
  for (const auto& c : r.kitti->classes) {
    md << "| " << className(c.cls) << " | " << c.curves[2][0].num_gt << " | " << c.curves[2][1].num_gt << " | "
       << c.curves[2][2].num_gt << " | " << c.num_det << " |\n";
  }
  {
    const KittiFalseBoxes& fb = r.kitti->false_boxes;
    const double nf = static_cast<double>(std::max<std::size_t>(1, r.kitti->num_frames));
    md << "\nFalse boxes (detections with BEV IoU < 0.1 against every label of any type and not in a DontCare "
          "region), per frame: **"
       << fmt(fb.total() / nf) << "** (Car " << fmt(fb.per_class[0] / nf) << ", Pedestrian "
       << fmt(fb.per_class[1] / nf) << ", Cyclist " << fmt(fb.per_class[2] / nf) << "); with score >= 0.5: "
       << fmt(fb.totalScore50() / nf) << ".\n";
  }
  md << "\n### Strict IoU thresholds (Car 0.7, Pedestrian 0.5, Cyclist 0.5)\n\n";
  kittiTable(md, *r.kitti, pngs, "kitti_");
  if (r.kitti_loose) {
    md << "### Loose IoU thresholds (Car 0.5, Pedestrian 0.25, Cyclist 0.25; keys kitti_loose.*)\n\n";
    kittiTable(md, *r.kitti_loose, pngs, "");
  }
}

void reportWaymo(std::ostringstream& md, const EvalReport& r, const std::vector<std::string>& pngs) {
  const auto& o = r.waymo_options;
  md << "## Waymo-style AP / APH (LiDAR frame, 360 degrees)\n\n"
     << "3D IoU thresholds: Car " << fmt(o.iou_threshold[0]) << ", Pedestrian " << fmt(o.iou_threshold[1])
     << ", Cyclist " << fmt(o.iou_threshold[2]) << ". Heading accuracy of a match: 1 - |dyaw| / pi (wrapped). ";
  if (r.waymo->used_point_counts) {
    md << "Levels from the LiDAR points in each ground-truth box: 0 points -> dropped (" << r.waymo->dropped_empty_gt
       << " boxes), 1.." << o.level2_max_points << " -> LEVEL_2, more -> LEVEL_1; L1 ignores LEVEL_2 boxes, L2 "
       << "evaluates both. ";
  } else {
    md << "No point counts were available (no counts in the ground truth, no scans): every box is LEVEL_1, so L1 "
          "and L2 agree. ";
  }
  md << "Matching: predictions in descending score order take the unmatched ground truth of highest IoU; AP = area "
        "under the max-precision-interpolated precision-recall curve (every score cutoff); APH the same on "
        "heading-weighted precision and recall. Van / Person_sitting are ignore regions.\n\n"
     << "| class | L1 AP | L1 APH | L2 AP | L2 APH | L1 GT | L2 GT | TP (L2) | FP (L2) |\n"
     << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const auto& c : r.waymo->classes) {
    md << "| " << className(c.cls) << " | " << fmt(c.levels[0].ap) << " | " << fmt(c.levels[0].aph) << " | "
       << fmt(c.levels[1].ap) << " | " << fmt(c.levels[1].aph) << " | " << c.levels[0].num_gt << " | "
       << c.levels[1].num_gt << " | " << c.levels[1].num_tp << " | " << c.levels[1].num_fp << " |\n";
  }
  md << "| mean | " << fmt(r.waymo->mean_ap[0]) << " | " << fmt(r.waymo->mean_aph[0]) << " | "
     << fmt(r.waymo->mean_ap[1]) << " | " << fmt(r.waymo->mean_aph[1]) << " | | | | |\n\n";
  md << "By range (horizontal distance from the sensor; ground truth outside the bin is ignored, predictions "
        "outside it dropped), L2 AP / APH:\n\n| class |";
  for (const auto& b : o.ranges) md << " " << b.name << " m |";
  md << "\n| --- |";
  for (std::size_t k = 0; k < o.ranges.size(); ++k) md << " ---: |";
  md << "\n";
  for (const auto& c : r.waymo->classes) {
    md << "| " << className(c.cls) << " |";
    for (const auto& rb : c.ranges) {
      md << " " << fmt(rb[1].ap) << " / " << fmt(rb[1].aph) << " (" << rb[1].num_gt << " GT) |";
    }
    md << "\n";
  }
  md << "\n";
  for (const auto& png : pngs) {
    if (png.rfind("waymo_", 0) == 0) md << "![" << png << "](plots/" << png << ")\n";
  }
  md << "\n";
}

void reportMot(std::ostringstream& md, const EvalReport& r) {
  const auto& o = r.mot_options;
  md << "## Tracking (CLEAR MOT and HOTA, per class)\n\n"
     << "Similarity: " << similarityName(o.similarity);
  if (o.similarity == MotSimilarity::CenterDistance) md << " (1 - d / " << fmt(o.zero_distance) << " m)";
  md << "; CLEAR matches need similarity >= " << fmt(o.threshold) << "; HOTA averages over alpha 0.05..0.95. ";
  if (o.max_range > 0)
    md << "Only boxes within " << fmt(o.max_range) << " m of the sensor (BEV) are evaluated, ground truth and "
       << "predictions alike. ";
  md << "MOTA, MOTP, HOTA, DetA, AssA in percent; IDSW and FRAG are counts; MT / ML in percent of ground-truth "
        "tracks (tracked > 80 % / < 20 % of their frames). Definitions as TrackEval. "
     << r.mot->num_sequences << " sequences; " << r.mot->removed_on_ignore
     << " predictions on ignored ground truth (Van, Person_sitting) removed.\n\n"
     << "| class | MOTA | MOTP | IDSW | FRAG | MT | ML | HOTA | DetA | AssA | GT | TP | FP | FN | GT tracks | "
        "pred tracks |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
        "---: | ---: | ---: | ---: |\n";
  for (const auto& c : r.mot->classes) {
    const double tracks = std::max(1, c.clear.num_gt_tracks);
    md << "| " << className(c.cls) << " | " << fmt(c.clear.mota) << " | " << fmt(c.clear.motp) << " | "
       << c.clear.idsw << " | " << c.clear.frag << " | " << fmt(100.0 * c.clear.mt / tracks) << " | "
       << fmt(100.0 * c.clear.ml / tracks) << " | " << fmt(c.hota.hota) << " | " << fmt(c.hota.deta) << " | "
       << fmt(c.hota.assa) << " | " << c.clear.num_gt << " | " << c.clear.tp << " | " << c.clear.fp << " | "
       << c.clear.fn << " | " << c.clear.num_gt_tracks << " | " << c.num_pred_tracks << " |\n";
  }
  md << "\n";
}

void reportIdStability(std::ostringstream& md, const EvalReport& r) {
  md << "## Track-id stability\n\n"
     << "Of the ground-truth track-frames an output object covers (per frame and class, Hungarian on centre "
        "distance < "
     << fmt(r.id_stability_options.max_center_distance)
     << " m), the share whose output id is the one that ground-truth track was covered by most often (stability); "
        "coverage = covered / all ground-truth track-frames. Percent.\n\n"
     << "| class | stability | coverage | GT track-frames | covered | stable | GT tracks covered | output ids |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  auto row = [&md](const std::string& name, const IdStabilityCounts& c) {
    md << "| " << name << " | " << fmt(c.stability()) << " | " << fmt(c.coverage()) << " | " << c.gt_track_frames
       << " | " << c.matched << " | " << c.stable << " | " << c.gt_tracks << " | " << c.output_ids << " |\n";
  };
  for (const auto& c : r.id_stability->classes) row(className(c.cls), c.counts);
  row("all", r.id_stability->all);
  md << "\n";
}

}  // namespace

std::vector<std::string> writeReport(const std::string& dir, const EvalReport& r) {
  fs::create_directories(dir);
  Plots plots(pathJoin(dir, "plots"));
  fs::create_directories(plots.dir());
  const auto metrics = metricsMap(r);
  writeFile(pathJoin(dir, "metrics.json"), metricsJson(metrics));

  if (r.kitti) plotKitti(r, &plots);
  if (r.waymo) plotWaymo(r, &plots);

  if (r.min_points > 0) writeFile(pathJoin(dir, "label_returns.csv"), labelReturnsCsv(r.label_returns));

  std::ostringstream md;
  reportInputs(md, r);
  if (r.min_points > 0) reportMinPoints(md, r);
  if (r.kitti) reportKitti(md, r, plots.pngs());
  if (r.waymo) reportWaymo(md, r, plots.pngs());
  if (r.mot) reportMot(md, r);
  if (r.id_stability) reportIdStability(md, r);
  writeFile(pathJoin(dir, "report.md"), md.str());
  return plots.pngs();
}

}  // namespace eval
}  // namespace ret3d
