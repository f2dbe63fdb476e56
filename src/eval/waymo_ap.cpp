#include "ret3d/eval/waymo_ap.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "ret3d/core/geometry.h"
#include "assignment.h"
#include "parallel.h"

namespace ret3d {
namespace eval {

const char* levelKey(WaymoLevel level) { return level == WaymoLevel::L1 ? "L1" : "L2"; }

double headingAccuracy(double yaw_pred, double yaw_gt) {
  return 1.0 - std::abs(wrapAngle(yaw_pred - yaw_gt)) / M_PI;
}

double interpolatedAp(const std::vector<double>& recall, const std::vector<double>& precision) {
  const std::size_t n = std::min(recall.size(), precision.size());
  std::vector<double> p(precision.begin(), precision.begin() + n);
  for (std::size_t k = n; k-- > 1;) p[k - 1] = std::max(p[k - 1], p[k]);
  double ap = 0, prev_r = 0;
  for (std::size_t k = 0; k < n; ++k) {
    ap += std::max(0.0, recall[k] - prev_r) * p[k];
    prev_r = std::max(prev_r, recall[k]);
  }
  return 100.0 * ap;
}

namespace {

// One class in one frame: its ground truth and predictions and their 3D IoUs.
struct ClassFrame {
  std::vector<const Box*> gt;
  std::vector<char> gt_ignore;
  std::vector<const Box*> pred;  // sorted by descending score
  std::vector<double> iou;       // pred x gt
};

// The change of one frame's counts when the score cutoff comes down to `score`: the curve is their running sum.
struct Step {
  double score;
  double tp, fp, heading;
};

double horizontalRange(const Box& b) { return std::hypot(b.x, b.y); }

// Hungarian assignment of some candidates to some valid ground truth (one connected part of their IoU graph),
// maximising the total IoU of the pairs at or above the threshold. Sets, per candidate row, whether it is matched
// and its heading accuracy.
void assignPart(const ClassFrame& cf, const std::vector<std::size_t>& rows, const std::vector<std::size_t>& cols,
                double threshold, std::vector<char>* matched, std::vector<double>* heading,
                const std::vector<std::size_t>& candidates) {
  const std::size_t ng = cf.gt.size(), nr = rows.size(), nc = cols.size();
  std::vector<double> weight(nr * nc, 0.0);  // pairs under the threshold weigh nothing: never a match
  for (std::size_t r = 0; r < nr; ++r) {
    for (std::size_t c = 0; c < nc; ++c) {
      const double o = cf.iou[candidates[rows[r]] * ng + cols[c]];
      if (o >= threshold) weight[r * nc + c] = o;
    }
  }
  const std::vector<int> assign = detail::maximiseAssignment(weight, static_cast<int>(nr), static_cast<int>(nc));
  for (std::size_t r = 0; r < nr; ++r) {
    const bool hit = assign[r] >= 0 && weight[r * nc + assign[r]] > 0;
    (*matched)[rows[r]] = hit;
    (*heading)[rows[r]] = hit ? headingAccuracy(cf.pred[candidates[rows[r]]]->yaw, cf.gt[cols[assign[r]]]->yaw) : 0.0;
  }
}

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Waymo's matching of one frame under one configuration, at every cutoff among the frame's own prediction scores
// (the curve's breakpoints: between them the frame's matching cannot change). At each, the candidates (counted
// predictions at or above the cutoff reaching the threshold on some valid ground truth) are assigned anew, part by
// part of their IoU graph: only the parts a new candidate joins can change. Appends the frame's steps to `out` and
// returns the number of valid ground truth.
int matchFrame(const ClassFrame& cf, const std::vector<char>& gt_valid, const std::vector<char>& pred_used,
               double threshold, std::vector<Step>& out) {
  const std::size_t ng = cf.gt.size(), np = cf.pred.size();
  int n_valid = 0;
  for (std::size_t g = 0; g < ng; ++g) n_valid += gt_valid[g];
  std::vector<std::size_t> candidates;  // prediction indices
  std::vector<char> on_ignored, matched;  // per candidate
  std::vector<double> heading;            // per candidate: its heading accuracy when matched
  double unmatchable_fp = 0;              // counted predictions above the cutoff overlapping no ground truth
  double tp = 0, fp = 0, h = 0;           // at the previous cutoff
  for (std::size_t p = 0; p < np;) {
    const double score = cf.pred[p]->score;
    const std::size_t first_new = candidates.size();
    for (; p < np && cf.pred[p]->score == score; ++p) {  // ties enter together
      if (!pred_used[p]) continue;
      bool valid = false, ignored = false;
      for (std::size_t g = 0; g < ng; ++g) {
        if (cf.iou[p * ng + g] < threshold) continue;
        (gt_valid[g] ? valid : ignored) = true;
      }
      if (valid) {
        candidates.push_back(p);
        on_ignored.push_back(ignored);
        matched.push_back(0);
        heading.push_back(0.0);
      } else if (!ignored) {
        unmatchable_fp += 1;
      }  // else on an ignored box only: dropped
    }
    const std::size_t nc = candidates.size();
    if (nc > first_new) {
      // Parts of the graph: candidates are nodes [0, nc), ground truth g is node nc + g.
      std::vector<int> parent(nc + ng);
      std::iota(parent.begin(), parent.end(), 0);
      for (std::size_t k = 0; k < nc; ++k) {
        for (std::size_t g = 0; g < ng; ++g) {
          if (gt_valid[g] && cf.iou[candidates[k] * ng + g] >= threshold)
            parent[findRoot(parent, static_cast<int>(k))] = findRoot(parent, static_cast<int>(nc + g));
        }
      }
      std::vector<char> redo(nc + ng, 0);
      for (std::size_t k = first_new; k < nc; ++k) redo[findRoot(parent, static_cast<int>(k))] = 1;
      std::vector<std::vector<std::size_t>> rows(nc + ng), cols(nc + ng);
      for (std::size_t k = 0; k < nc; ++k) {
        const int r = findRoot(parent, static_cast<int>(k));
        if (redo[r]) rows[r].push_back(k);
      }
      for (std::size_t g = 0; g < ng; ++g) {
        const int r = findRoot(parent, static_cast<int>(nc + g));
        if (gt_valid[g] && redo[r]) cols[r].push_back(g);
      }
      for (std::size_t r = 0; r < nc + ng; ++r)
        if (!rows[r].empty()) assignPart(cf, rows[r], cols[r], threshold, &matched, &heading, candidates);
    }
    // A candidate left unmatched is a false positive unless it overlaps an ignored box (then dropped, as above).
    double new_tp = 0, new_fp = unmatchable_fp, new_h = 0;
    for (std::size_t k = 0; k < nc; ++k) {
      new_tp += matched[k];
      new_h += heading[k];
      new_fp += !matched[k] && !on_ignored[k];
    }
    if (new_tp != tp || new_fp != fp || new_h != h) out.push_back({score, new_tp - tp, new_fp - fp, new_h - h});
    tp = new_tp, fp = new_fp, h = new_h;
  }
  return n_valid;
}

WaymoCurve curveFrom(std::vector<Step> steps, int num_gt) {
  WaymoCurve c;
  c.num_gt = num_gt;
  std::stable_sort(steps.begin(), steps.end(), [](const Step& a, const Step& b) { return a.score > b.score; });
  double tp = 0, fp = 0, h = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    tp += steps[i].tp;
    fp += steps[i].fp;
    h += steps[i].heading;
    // One curve point per distinct score: ties are cut together.
    if (i + 1 < steps.size() && steps[i + 1].score == steps[i].score) continue;
    if (tp + fp <= 0) continue;
    const double n = std::max(1, num_gt);
    c.recall.push_back(tp / n);
    c.precision.push_back(tp / (tp + fp));
    c.recall_h.push_back(h / n);
    c.precision_h.push_back(h / (tp + fp));
  }
  c.num_tp = static_cast<int>(std::lround(tp));
  c.num_fp = static_cast<int>(std::lround(fp));
  if (num_gt > 0) {
    c.ap = interpolatedAp(c.recall, c.precision);
    c.aph = interpolatedAp(c.recall_h, c.precision_h);
  }
  return c;
}

// One frame's boxes of class `cls` (predictions in descending score) and their IoUs, computed once and shared by
// every level and range; a ground-truth box without returns is not ground truth when point counts are used (counted
// in *dropped).
ClassFrame classFrame(const EvalFrame& f, ObjectClass cls, bool use_point_counts, std::size_t* dropped) {
  ClassFrame cf;
  for (std::size_t g = 0; g < f.gt_boxes.size(); ++g) {
    const Box& b = f.gt_boxes[g];
    if (b.label != cls) continue;
    const bool ignore = g < f.gt_ignore.size() && f.gt_ignore[g];
    if (use_point_counts && b.num_points == 0 && !ignore) {
      ++*dropped;
      continue;
    }
    cf.gt.push_back(&b);
    cf.gt_ignore.push_back(ignore);
  }
  for (const Box& b : f.pred_boxes) {
    if (b.label == cls) cf.pred.push_back(&b);
  }
  std::stable_sort(cf.pred.begin(), cf.pred.end(), [](const Box* a, const Box* b) { return a->score > b->score; });
  cf.iou.resize(cf.pred.size() * cf.gt.size());
  for (std::size_t p = 0; p < cf.pred.size(); ++p) {
    for (std::size_t g = 0; g < cf.gt.size(); ++g) cf.iou[p * cf.gt.size() + g] = iou3d(*cf.pred[p], *cf.gt[g]);
  }
  return cf;
}

// The precision / recall curve of one configuration: a difficulty level (0: LEVEL_1, without the boxes of at most
// level2_max_points returns) over all ranges (range < 0) or over one range bin, for both ground truth and predictions.
WaymoCurve configurationCurve(const std::vector<ClassFrame>& cfs, const WaymoOptions& options, int level, int range,
                              double iou_threshold) {
  std::vector<Step> dets;
  int num_gt = 0;
  std::vector<char> valid, pred_used;
  for (const ClassFrame& cf : cfs) {
    valid.assign(cf.gt.size(), 1);
    pred_used.assign(cf.pred.size(), 1);
    for (std::size_t g = 0; g < cf.gt.size(); ++g) {
      const bool level2 =
          options.use_point_counts && static_cast<int>(cf.gt[g]->num_points) <= options.level2_max_points;
      const bool out_of_range =
          range >= 0 && (horizontalRange(*cf.gt[g]) < options.ranges[range].min ||
                         horizontalRange(*cf.gt[g]) >= options.ranges[range].max);
      valid[g] = !cf.gt_ignore[g] && !(level == 0 && level2) && !out_of_range;
    }
    if (range >= 0) {
      for (std::size_t p = 0; p < cf.pred.size(); ++p) {
        const double r = horizontalRange(*cf.pred[p]);
        pred_used[p] = r >= options.ranges[range].min && r < options.ranges[range].max;
      }
    }
    num_gt += matchFrame(cf, valid, pred_used, iou_threshold, dets);
  }
  return curveFrom(std::move(dets), num_gt);
}

// mAP and mAPH per level: the mean over the classes that have ground truth at that level.
void averageOverClasses(WaymoResult& result) {
  for (int l = 0; l < kWaymoNumLevels; ++l) {
    int n = 0;
    for (const auto& cr : result.classes) {
      if (cr.levels[l].num_gt == 0) continue;
      result.mean_ap[l] += cr.levels[l].ap;
      result.mean_aph[l] += cr.levels[l].aph;
      ++n;
    }
    if (n > 0) {
      result.mean_ap[l] /= n;
      result.mean_aph[l] /= n;
    }
  }
}

}  // namespace

WaymoResult evaluateWaymo(const std::vector<EvalFrame>& frames, const WaymoOptions& options) {
  WaymoResult result;
  result.used_point_counts = options.use_point_counts;
  const std::size_t nc = options.classes.size();
  const std::size_t nr = options.ranges.size();
  detail::ProgressCounter progress(options.progress, nc * (1 + kWaymoNumLevels * (1 + nr)));
  result.classes.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    WaymoClassResult& cr = result.classes[c];
    cr.cls = options.classes[c];
    const int ci = static_cast<int>(cr.cls) - 1;
    if (ci < 0 || ci > 2) throw std::invalid_argument("evaluateWaymo: only Car, Pedestrian and Cyclist are evaluated");
    cr.iou_threshold = options.iou_threshold[ci];

    std::vector<ClassFrame> cfs(frames.size());
    std::vector<std::size_t> dropped(frames.size(), 0);
    detail::parallelFor(frames.size(), options.threads, [&](std::size_t i) {
      cfs[i] = classFrame(frames[i], cr.cls, options.use_point_counts, &dropped[i]);
    });
    for (std::size_t n : dropped) result.dropped_empty_gt += n;
    progress.tick();

    // Configurations: each level over all ranges, then each (range, level).
    const std::size_t n_configs = kWaymoNumLevels * (1 + nr);
    cr.ranges.resize(nr);
    detail::parallelFor(n_configs, options.threads, [&](std::size_t k) {
      const int level = static_cast<int>(k % kWaymoNumLevels);
      const int range = static_cast<int>(k / kWaymoNumLevels) - 1;  // -1: all ranges
      WaymoCurve curve = configurationCurve(cfs, options, level, range, cr.iou_threshold);
      if (range < 0) {
        cr.levels[level] = std::move(curve);
      } else {
        cr.ranges[range][level] = std::move(curve);
      }
      progress.tick();
    });
  }
  averageOverClasses(result);
  return result;
}

}  // namespace eval
}  // namespace ret3d
