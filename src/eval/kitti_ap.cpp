// A port of the KITTI object devkit's evaluation (evaluate_object_3d_offline.cpp, with the 2017 fix that lets a
// ground truth fall back on a below-minimum-height detection). The control flow of cleanData, computeStatistics,
// getThresholds and eval_class is kept step for step, quirks included, because agreement with published numbers is
// the point; only the overlaps are computed once per frame and reused for every class, difficulty and threshold.
#include "ret3d/eval/kitti_ap.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <strings.h>

#include "ret3d/core/geometry.h"
#include "ret3d/core/enum_names.h"
#include "parallel.h"

namespace ret3d {
namespace eval {

const char* metricKey(KittiMetric m) {
  static constexpr std::array<const char*, kKittiNumMetrics> kNames = {"2d", "bev", "3d"};
  static_assert(static_cast<int>(KittiMetric::Box3D) + 1 == kKittiNumMetrics);
  return enumName(m, kNames);
}

const char* difficultyKey(KittiDifficulty d) {
  static constexpr std::array<const char*, kKittiNumDifficulties> kNames = {"easy", "moderate", "hard"};
  static_assert(static_cast<int>(KittiDifficulty::Hard) + 1 == kKittiNumDifficulties);
  return enumName(d, kNames);
}

double kittiAp11(const std::vector<double>& precision) {
  double sum = 0;
  for (std::size_t i = 0; i < precision.size() && i < static_cast<std::size_t>(kKittiSamplePoints); i += 4) {
    sum += precision[i];
  }
  return sum / 11.0 * 100.0;
}

double kittiAp40(const std::vector<double>& precision) {
  double sum = 0;
  for (std::size_t i = 1; i < precision.size() && i < static_cast<std::size_t>(kKittiSamplePoints); ++i) {
    sum += precision[i];
  }
  return sum / 40.0 * 100.0;
}

double KittiCurve::ap11() const { return kittiAp11(precision); }
double KittiCurve::ap40() const { return kittiAp40(precision); }

double kittiImageOverlap(const kitti::Label& det, const kitti::Label& gt, int criterion) {
  const auto& a = det.bbox;
  const auto& b = gt.bbox;
  const double w = std::min(a[2], b[2]) - std::max(a[0], b[0]);
  const double h = std::min(a[3], b[3]) - std::max(a[1], b[1]);
  if (w <= 0 || h <= 0) return 0;
  const double inter = w * h;
  if (criterion == -1) return iou2d(a, b);
  const double area = criterion == 0 ? (a[2] - a[0]) * (a[3] - a[1]) : (b[2] - b[0]) * (b[3] - b[1]);
  return area > 0 ? inter / area : 0;
}

namespace {

// The ground-plane rectangle of a camera label as a core Box in the (x, z) plane. The devkit rotates the corners
// (+-l/2, +-w/2) by [[cos ry, sin ry], [-sin ry, cos ry]], i.e. by -ry in (x, z): hence yaw = -rotation_y.
Box groundBox(const kitti::Label& l) {
  Box b;
  b.x = l.x;
  b.y = l.z;
  b.length = l.l;
  b.width = l.w;
  b.yaw = -l.rotation_y;
  return b;
}

double overlapFromAreas(double inter, double a, double b, int criterion) {
  double denom = criterion == -1 ? a + b - inter : criterion == 0 ? a : b;
  return denom > 0 ? inter / denom : 0;
}

}  // namespace

double kittiBevOverlap(const kitti::Label& det, const kitti::Label& gt, int criterion) {
  const double inter = bevIntersectionArea(groundBox(det), groundBox(gt));
  return overlapFromAreas(inter, std::abs(det.l * det.w), std::abs(gt.l * gt.w), criterion);
}

double kitti3dOverlap(const kitti::Label& det, const kitti::Label& gt, int criterion) {
  // Camera y points down and y is the bottom of the box: it spans [y - h, y].
  const double ymax = std::min(det.y, gt.y);
  const double ymin = std::max(det.y - det.h, gt.y - gt.h);
  const double dy = std::max(0.0, ymax - ymin);
  if (dy <= 0) return 0;
  const double inter = bevIntersectionArea(groundBox(det), groundBox(gt)) * dy;
  return overlapFromAreas(inter, det.h * det.l * det.w, gt.h * gt.l * gt.w, criterion);
}

std::vector<double> kittiThresholds(std::vector<double> v, int num_gt) {
  std::vector<double> t;
  std::sort(v.begin(), v.end(), std::greater<double>());
  const double n = num_gt;
  double current_recall = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    // Skip this score when the next one's recall is closer to the current recall step.
    const double l_recall = static_cast<double>(i + 1) / n;
    const double r_recall = i + 1 < v.size() ? static_cast<double>(i + 2) / n : l_recall;
    if ((r_recall - current_recall) < (current_recall - l_recall) && i + 1 < v.size()) continue;
    t.push_back(v[i]);
    current_recall += 1.0 / (kKittiSamplePoints - 1.0);
  }
  return t;
}

std::vector<double> kittiExactSamples(const std::vector<double>& recall, const std::vector<double>& precision) {
  std::vector<double> out(kKittiSamplePoints, 0.0);
  for (int k = 0; k < kKittiSamplePoints; ++k) {
    const double r = static_cast<double>(k) / (kKittiSamplePoints - 1);
    for (std::size_t t = 0; t < recall.size() && t < precision.size(); ++t)
      if (recall[t] >= r - 1e-12) out[static_cast<std::size_t>(k)] = std::max(out[static_cast<std::size_t>(k)], precision[t]);
  }
  return out;
}

namespace {

bool sameType(const std::string& a, const char* b) { return strcasecmp(a.c_str(), b) == 0; }

// Overlaps of one frame for one metric: every detection against every ground truth (criterion -1) and against
// every DontCare region (criterion 0, i.e. over the detection's area).
struct FrameOverlaps {
  int nd = 0, ng = 0;
  std::vector<int> dontcare;     // gt indices of DontCare labels
  std::vector<double> iou;       // nd x ng
  std::vector<double> dc;        // nd x dontcare.size()
  double at(int d, int g) const { return iou[static_cast<std::size_t>(d) * ng + g]; }
  double dcAt(int d, int k) const { return dc[static_cast<std::size_t>(d) * dontcare.size() + k]; }
};

using OverlapFn = double (*)(const kitti::Label&, const kitti::Label&, int);

FrameOverlaps computeOverlaps(const KittiFrame& f, OverlapFn fn) {
  FrameOverlaps o;
  o.nd = static_cast<int>(f.det.size());
  o.ng = static_cast<int>(f.gt.size());
  for (int g = 0; g < o.ng; ++g) {
    if (sameType(f.gt[g].type, "DontCare")) o.dontcare.push_back(g);
  }
  o.iou.resize(static_cast<std::size_t>(o.nd) * o.ng);
  o.dc.resize(static_cast<std::size_t>(o.nd) * o.dontcare.size());
  for (int d = 0; d < o.nd; ++d) {
    for (int g = 0; g < o.ng; ++g) o.iou[static_cast<std::size_t>(d) * o.ng + g] = fn(f.det[d], f.gt[g], -1);
    for (std::size_t k = 0; k < o.dontcare.size(); ++k) {
      o.dc[d * o.dontcare.size() + k] = fn(f.det[d], f.gt[o.dontcare[k]], 0);
    }
  }
  return o;
}

// devkit cleanData: ignored_gt 0 = valid, 1 = ignored (neighbouring class or too hard), -1 = other class;
// ignored_det 0 = valid, 1 = below the minimum height (any class), -1 = other class.
int cleanData(const KittiFrame& f, ObjectClass cls, int diff, std::vector<int>& ignored_gt,
              std::vector<int>& ignored_det) {
  const char* name = className(cls);
  int n_gt = 0;
  ignored_gt.clear();
  ignored_det.clear();
  for (std::size_t i = 0; i < f.gt.size(); ++i) {
    const kitti::Label& g = f.gt[i];
    const double height = g.bbox[3] - g.bbox[1];
    int valid_class;
    if (sameType(g.type, name)) {
      valid_class = 1;
    } else if (cls == ObjectClass::Pedestrian && sameType(g.type, "Person_sitting")) {
      valid_class = 0;
    } else if (cls == ObjectClass::Car && sameType(g.type, "Van")) {
      valid_class = 0;
    } else {
      valid_class = -1;
    }
    const bool ignore = g.occluded > kKittiMaxOcclusion[diff] || g.truncated > kKittiMaxTruncation[diff] ||
                        height < kKittiMinHeight[diff] || (i < f.gt_ignore.size() && f.gt_ignore[i]);
    if (valid_class == 1 && !ignore) {
      ignored_gt.push_back(0);
      ++n_gt;
    } else if (valid_class == 0 || (ignore && valid_class == 1)) {
      ignored_gt.push_back(1);
    } else {
      ignored_gt.push_back(-1);
    }
  }
  for (const auto& d : f.det) {
    const int valid_class = sameType(d.type, name) ? 1 : -1;
    // The devkit truncates the detection's height to an integer (int32_t height = fabs(y1 - y2)).
    const int height = static_cast<int>(std::fabs(d.bbox[1] - d.bbox[3]));
    if (height < kKittiMinHeight[diff]) {
      ignored_det.push_back(1);
    } else if (valid_class == 1) {
      ignored_det.push_back(0);
    } else {
      ignored_det.push_back(-1);
    }
  }
  return n_gt;
}

struct Stat {
  int tp = 0, fp = 0, fn = 0;
  double similarity = 0;
};

double score(const kitti::Label& d) { return d.score ? *d.score : 0.0; }

// devkit computeStatistics. Without compute_fp it collects the scores of true positives (highest-scoring candidate
// per ground truth) into tp_scores; with compute_fp it counts TP/FP/FN at `thresh` (greatest-overlap candidate).
Stat computeStatistics(const KittiFrame& f, const FrameOverlaps& ov, const std::vector<int>& ignored_gt,
                       const std::vector<int>& ignored_det, bool compute_fp, double min_overlap, bool compute_aos,
                       double thresh, std::vector<double>* tp_scores, std::vector<char>& assigned,
                       std::vector<char>& below) {
  Stat stat;
  const double kNoDetection = -10000000;
  const int nd = ov.nd;
  assigned.assign(nd, 0);
  below.assign(nd, 0);
  if (compute_fp) {
    for (int j = 0; j < nd; ++j) below[j] = score(f.det[j]) < thresh;
  }
  int n_delta = 0;
  double sim_sum = 0;
  for (int i = 0; i < ov.ng; ++i) {
    if (ignored_gt[i] == -1) continue;
    int det_idx = -1;
    double valid_detection = kNoDetection;
    double max_overlap = 0;
    bool assigned_ignored_det = false;
    for (int j = 0; j < nd; ++j) {
      if (ignored_det[j] == -1 || assigned[j] || below[j]) continue;
      const double overlap = ov.at(j, i);
      if (!compute_fp && overlap > min_overlap && score(f.det[j]) > valid_detection) {
        det_idx = j;
        valid_detection = score(f.det[j]);
      } else if (compute_fp && overlap > min_overlap && (overlap > max_overlap || assigned_ignored_det) &&
                 ignored_det[j] == 0) {
        max_overlap = overlap;
        det_idx = j;
        valid_detection = 1;
        assigned_ignored_det = false;
      } else if (compute_fp && overlap > min_overlap && valid_detection == kNoDetection && ignored_det[j] == 1) {
        det_idx = j;
        valid_detection = 1;
        assigned_ignored_det = true;
      }
    }
    if (valid_detection == kNoDetection && ignored_gt[i] == 0) {
      ++stat.fn;
    } else if (valid_detection != kNoDetection && (ignored_gt[i] == 1 || ignored_det[det_idx] == 1)) {
      assigned[det_idx] = 1;
    } else if (valid_detection != kNoDetection) {
      ++stat.tp;
      if (tp_scores) tp_scores->push_back(score(f.det[det_idx]));
      if (compute_aos) {
        sim_sum += (1.0 + std::cos(f.gt[i].alpha - f.det[det_idx].alpha)) / 2.0;
        ++n_delta;
      }
      assigned[det_idx] = 1;
    }
  }
  if (compute_fp) {
    for (int j = 0; j < nd; ++j) {
      if (!(assigned[j] || ignored_det[j] == -1 || ignored_det[j] == 1 || below[j])) ++stat.fp;
    }
    // Detections inside DontCare regions are not false positives.
    int nstuff = 0;
    for (std::size_t k = 0; k < ov.dontcare.size(); ++k) {
      for (int j = 0; j < nd; ++j) {
        if (assigned[j] || ignored_det[j] == -1 || ignored_det[j] == 1 || below[j]) continue;
        if (ov.dcAt(j, static_cast<int>(k)) > min_overlap) {
          assigned[j] = 1;
          ++nstuff;
        }
      }
    }
    stat.fp -= nstuff;
    if (compute_aos) {
      // False positives have similarity 0; a frame with neither TP nor FP does not count (similarity -1).
      stat.similarity = (stat.tp > 0 || stat.fp > 0) ? sim_sum : -1;
    }
  }
  return stat;
}

// devkit eval_class for one class, difficulty and metric.
void evalClass(const std::vector<KittiFrame>& frames, const std::vector<FrameOverlaps>& overlaps, ObjectClass cls,
               int diff, double min_overlap, bool compute_aos, bool exact_recall, KittiCurve& precision,
               KittiCurve* aos) {
  const std::size_t nf = frames.size();
  std::vector<std::vector<int>> ignored_gt(nf), ignored_det(nf);
  std::vector<double> v;
  std::vector<char> assigned, below;
  int n_gt = 0;
  for (std::size_t i = 0; i < nf; ++i) {
    n_gt += cleanData(frames[i], cls, diff, ignored_gt[i], ignored_det[i]);
    computeStatistics(frames[i], overlaps[i], ignored_gt[i], ignored_det[i], false, min_overlap, false, 0, &v,
                      assigned, below);
  }
  std::vector<double> thresholds;
  if (exact_recall) {
    thresholds = v;  // every true positive's score, highest first
    std::sort(thresholds.begin(), thresholds.end(), std::greater<double>());
    thresholds.erase(std::unique(thresholds.begin(), thresholds.end()), thresholds.end());
  } else {
    thresholds = kittiThresholds(v, n_gt);
    if (thresholds.size() > static_cast<std::size_t>(kKittiSamplePoints)) thresholds.resize(kKittiSamplePoints);
  }
  std::vector<Stat> pr(thresholds.size());
  for (std::size_t i = 0; i < nf; ++i) {
    for (std::size_t t = 0; t < thresholds.size(); ++t) {
      const Stat s = computeStatistics(frames[i], overlaps[i], ignored_gt[i], ignored_det[i], true, min_overlap,
                                       compute_aos, thresholds[t], nullptr, assigned, below);
      pr[t].tp += s.tp;
      pr[t].fp += s.fp;
      pr[t].fn += s.fn;
      if (s.similarity != -1) pr[t].similarity += s.similarity;
    }
  }
  precision = KittiCurve();
  precision.num_gt = n_gt;
  precision.thresholds = thresholds;
  if (aos) {
    *aos = KittiCurve();
    aos->num_gt = n_gt;
    aos->thresholds = thresholds;
  }
  if (exact_recall) {
    std::vector<double> p, a;
    for (std::size_t t = 0; t < thresholds.size(); ++t) {
      const double tp = pr[t].tp, fp = pr[t].fp, fn = pr[t].fn;
      precision.recall.push_back(tp + fn > 0 ? tp / (tp + fn) : 0.0);
      p.push_back(tp + fp > 0 ? tp / (tp + fp) : 0.0);
      a.push_back(tp + fp > 0 ? pr[t].similarity / (tp + fp) : 0.0);
    }
    precision.precision = kittiExactSamples(precision.recall, p);
    if (aos) aos->recall = precision.recall, aos->precision = kittiExactSamples(precision.recall, a);
    return;
  }
  for (std::size_t t = 0; t < thresholds.size(); ++t) {
    const double tp = pr[t].tp, fp = pr[t].fp, fn = pr[t].fn;
    precision.recall.push_back(tp + fn > 0 ? tp / (tp + fn) : 0.0);
    precision.precision[t] = tp + fp > 0 ? tp / (tp + fp) : 0.0;
    if (aos) aos->precision[t] = tp + fp > 0 ? pr[t].similarity / (tp + fp) : 0.0;
  }
  if (aos) aos->recall = precision.recall;
  // Interpolate: precision at a recall point is the best precision at that recall or beyond.
  for (std::size_t t = 0; t < thresholds.size(); ++t) {
    precision.precision[t] = *std::max_element(precision.precision.begin() + t, precision.precision.end());
    if (aos) aos->precision[t] = *std::max_element(aos->precision.begin() + t, aos->precision.end());
  }
}

OverlapFn overlapFor(int metric) {
  switch (static_cast<KittiMetric>(metric)) {
    case KittiMetric::Box2D:
      return kittiImageOverlap;
    case KittiMetric::Bev:
      return kittiBevOverlap;
    case KittiMetric::Box3D:
      return kitti3dOverlap;
  }
  return kittiImageOverlap;
}

}  // namespace

namespace {

KittiFalseBoxes countFalseBoxes(const std::vector<KittiFrame>& frames, const std::vector<ObjectClass>& classes) {
  constexpr double kMatched = 0.1, kDontCare = 0.5;
  KittiFalseBoxes out;
  for (const KittiFrame& f : frames) {
    for (const kitti::Label& d : f.det) {
      const auto cls = classFromName(d.type);
      if (!cls || std::find(classes.begin(), classes.end(), *cls) == classes.end()) continue;
      bool matched = false;
      for (const kitti::Label& g : f.gt) {
        matched = sameType(g.type, "DontCare") ? kittiImageOverlap(d, g, 0) > kDontCare
                                               : kittiBevOverlap(d, g, -1) >= kMatched;
        if (matched) break;
      }
      if (matched) continue;
      const std::size_t k = static_cast<std::size_t>(*cls) - 1;
      ++out.per_class[k];
      if (score(d) >= 0.5) ++out.per_class_score50[k];
    }
  }
  return out;
}

}  // namespace

KittiResult evaluateKitti(const std::vector<KittiFrame>& frames, const KittiApOptions& options) {
  KittiResult result;
  result.num_frames = frames.size();
  result.exact_recall = options.exact_recall;
  for (const auto& f : frames) {
    for (const auto& d : f.det) {
      if (d.alpha == -10) result.aos_valid = false;
    }
  }
  const std::size_t nc = options.classes.size();
  result.classes.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    auto& cr = result.classes[c];
    cr.cls = options.classes[c];
    const int ci = static_cast<int>(cr.cls) - 1;
    if (ci < 0 || ci > 2) throw std::invalid_argument("evaluateKitti: only Car, Pedestrian and Cyclist are evaluated");
    cr.min_overlap = options.min_overlap[ci];
    for (const auto& f : frames) {
      for (const auto& d : f.det) cr.num_det += sameType(d.type, className(cr.cls));
    }
  }
  result.false_boxes = countFalseBoxes(frames, options.classes);

  // Work: overlaps in frame blocks for each metric, then one task per (class, difficulty) of that metric.
  const std::size_t kBlock = 256;
  const std::size_t blocks = (frames.size() + kBlock - 1) / kBlock;
  const std::size_t class_tasks = nc * kKittiNumDifficulties;
  detail::ProgressCounter progress(options.progress, kKittiNumMetrics * (blocks + class_tasks));
  for (int m = 0; m < kKittiNumMetrics; ++m) {
    std::vector<FrameOverlaps> overlaps(frames.size());
    const OverlapFn fn = overlapFor(m);
    detail::parallelFor(blocks, options.threads, [&](std::size_t b) {
      for (std::size_t i = b * kBlock; i < std::min(frames.size(), (b + 1) * kBlock); ++i) {
        overlaps[i] = computeOverlaps(frames[i], fn);
      }
      progress.tick();
    });
    detail::parallelFor(class_tasks, options.threads, [&](std::size_t task) {
      auto& cr = result.classes[task / kKittiNumDifficulties];
      const int diff = static_cast<int>(task % kKittiNumDifficulties);
      const bool with_aos = m == static_cast<int>(KittiMetric::Box2D) && result.aos_valid;
      evalClass(frames, overlaps, cr.cls, diff, cr.min_overlap, with_aos, options.exact_recall, cr.curves[m][diff],
                with_aos ? &cr.aos[diff] : nullptr);
      progress.tick();
    });
  }
  return result;
}

}  // namespace eval
}  // namespace ret3d
