// CLEAR MOT (Bernardin & Stiefelhagen, "Evaluating Multiple Object Tracking Performance: The CLEAR MOT Metrics",
// 2008) as TrackEval's clear.py computes it, and the per-class, per-sequence driver shared with HOTA (hota.cpp).
#include "ret3d/eval/mot_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/enum_names.h"
#include "ret3d/core/geometry.h"
#include "assignment.h"
#include "mot_sequence.h"
#include "parallel.h"

namespace ret3d {
namespace eval {

const char* similarityName(MotSimilarity s) {
  static constexpr std::array<const char*, 3> kNames = {"iou3d", "bev", "center"};
  static_assert(static_cast<std::size_t>(MotSimilarity::CenterDistance) + 1 == kNames.size());
  return enumName(s, kNames);
}

double motSimilarity(const Box& gt, const Box& pred, const MotOptions& options) {
  switch (options.similarity) {
    case MotSimilarity::Iou3d:
      return iou3d(gt, pred);
    case MotSimilarity::IouBev:
      return bevIoU(gt, pred);
    case MotSimilarity::CenterDistance:
      return std::max(0.0, 1.0 - (gt.center() - pred.center()).norm() / options.zero_distance);
  }
  return 0;
}

namespace {

constexpr double kEps = 2.220446049250313e-16;

struct ClearSums {
  int tp = 0, fp = 0, fn = 0, idsw = 0, frag = 0, mt = 0, pt = 0, ml = 0, gt_tracks = 0;
  double motp_sum = 0;
};

// TrackEval clear.py on one sequence of one class.
void accumulateClear(const detail::MotSequence& seq, double threshold, ClearSums& sums) {
  const int ng = seq.num_gt_ids;
  std::vector<int> gt_count(ng, 0), matched_count(ng, 0), frag_count(ng, 0);
  std::vector<int> prev_id(ng, -1), prev_step_id(ng, -1);  // -1 = NaN
  for (const detail::MotTimestep& t : seq.steps) {
    const std::size_t nr = t.gt_ids.size(), nc = t.pred_ids.size();
    // An empty side: nothing can match. Unlike TrackEval, the previous-frame matches end here too (see header).
    if (nr == 0 || nc == 0) {
      sums.fp += static_cast<int>(nc);
      sums.fn += static_cast<int>(nr);
      for (int id : t.gt_ids) ++gt_count[id];
      std::fill(prev_step_id.begin(), prev_step_id.end(), -1);
      continue;
    }
    // Keep last frame's matches first (bonus 1000), then maximise similarity; pairs below threshold are not allowed.
    std::vector<double> score(nr * nc);
    for (std::size_t g = 0; g < nr; ++g) {
      for (std::size_t p = 0; p < nc; ++p) {
        const double s = t.at(g, p);
        double v = (prev_step_id[t.gt_ids[g]] == t.pred_ids[p] ? 1000.0 : 0.0) + s;
        if (s < threshold - kEps) v = 0;
        score[g * nc + p] = v;
      }
    }
    const std::vector<int> assign = detail::maximiseAssignment(score, static_cast<int>(nr), static_cast<int>(nc));
    std::vector<int> matched_gt, matched_pred;
    for (std::size_t g = 0; g < nr; ++g) {
      if (assign[g] >= 0 && score[g * nc + assign[g]] > kEps) {
        matched_gt.push_back(t.gt_ids[g]);
        matched_pred.push_back(t.pred_ids[assign[g]]);
        sums.motp_sum += t.at(g, assign[g]);
      }
    }
    for (std::size_t k = 0; k < matched_gt.size(); ++k) {
      const int last = prev_id[matched_gt[k]];
      if (last >= 0 && last != matched_pred[k]) ++sums.idsw;
    }
    for (int id : t.gt_ids) ++gt_count[id];
    for (int id : matched_gt) ++matched_count[id];
    std::vector<char> was_tracked(ng);
    for (int g = 0; g < ng; ++g) was_tracked[g] = prev_step_id[g] >= 0;
    std::fill(prev_step_id.begin(), prev_step_id.end(), -1);
    for (std::size_t k = 0; k < matched_gt.size(); ++k) {
      prev_id[matched_gt[k]] = matched_pred[k];
      prev_step_id[matched_gt[k]] = matched_pred[k];
    }
    for (int id : matched_gt) {
      if (!was_tracked[id]) ++frag_count[id];
    }
    const int n = static_cast<int>(matched_gt.size());
    sums.tp += n;
    sums.fn += static_cast<int>(nr) - n;
    sums.fp += static_cast<int>(nc) - n;
  }
  for (int g = 0; g < ng; ++g) {
    if (gt_count[g] == 0) continue;
    ++sums.gt_tracks;
    const double ratio = static_cast<double>(matched_count[g]) / gt_count[g];
    if (ratio > 0.8) {
      ++sums.mt;
    } else if (ratio >= 0.2) {
      ++sums.pt;
    } else {
      ++sums.ml;
    }
    if (frag_count[g] > 0) sums.frag += frag_count[g] - 1;
  }
}

ClearMot finishClear(const ClearSums& s) {
  ClearMot c;
  c.tp = s.tp;
  c.fp = s.fp;
  c.fn = s.fn;
  c.idsw = s.idsw;
  c.frag = s.frag;
  c.mt = s.mt;
  c.pt = s.pt;
  c.ml = s.ml;
  c.num_gt_tracks = s.gt_tracks;
  c.num_gt = s.tp + s.fn;
  c.mota = 100.0 * (s.tp - s.fp - s.idsw) / std::max(1, s.tp + s.fn);
  c.motp = 100.0 * s.motp_sum / std::max(1, s.tp);
  return c;
}

std::string where(const EvalFrame& f) {
  std::ostringstream oss;
  if (!f.sequence.empty()) oss << "sequence " << f.sequence << ", ";
  oss << "frame " << f.frame;
  return oss.str();
}

// One class of one sequence (frames [begin, end)): ignored ground truth and the predictions matched to it removed,
// ids mapped to 0..n-1, similarities computed.
detail::MotSequence prepare(const std::vector<EvalFrame>& frames, std::size_t begin, std::size_t end, ObjectClass cls,
                            const MotOptions& options, std::size_t& removed, int& num_pred_tracks) {
  detail::MotSequence seq;
  std::map<std::uint32_t, int> gt_ids, pred_ids;
  auto inRange = [&](const Box& b) { return !(options.max_range > 0) || std::hypot(b.x, b.y) <= options.max_range; };
  for (std::size_t i = begin; i < end; ++i) {
    const EvalFrame& f = frames[i];
    std::vector<const Box*> gt, ignored, pred;
    for (std::size_t g = 0; g < f.gt_boxes.size(); ++g) {
      const Box& b = f.gt_boxes[g];
      if (b.label != cls || !inRange(b)) continue;
      if (g < f.gt_ignore.size() && f.gt_ignore[g]) {
        ignored.push_back(&b);
        continue;
      }
      if (b.track_id == 0) {
        throw std::invalid_argument("tracking metrics: a ground-truth " + std::string(className(cls)) +
                                    " has no track id (" + where(f) + ")");
      }
      gt.push_back(&b);
    }
    for (const Box& b : f.pred_boxes) {
      if (b.label != cls || !inRange(b)) continue;
      if (b.track_id == 0) {
        throw std::invalid_argument("tracking metrics: a predicted " + std::string(className(cls)) +
                                    " has no track id (" + where(f) + ")");
      }
      pred.push_back(&b);
    }
    if (!ignored.empty() && !pred.empty()) {
      // Predictions that the optimal matching puts on an ignored box (similarity >= threshold) are removed.
      const std::size_t n_all = gt.size() + ignored.size();
      std::vector<double> score(n_all * pred.size());
      for (std::size_t g = 0; g < n_all; ++g) {
        const Box& gb = g < gt.size() ? *gt[g] : *ignored[g - gt.size()];
        for (std::size_t p = 0; p < pred.size(); ++p) {
          const double s = motSimilarity(gb, *pred[p], options);
          score[g * pred.size() + p] = s >= options.threshold - kEps ? s : 0.0;
        }
      }
      const auto assign =
          detail::maximiseAssignment(score, static_cast<int>(n_all), static_cast<int>(pred.size()));
      std::vector<char> drop(pred.size(), 0);
      for (std::size_t g = gt.size(); g < n_all; ++g) {
        if (assign[g] >= 0 && score[g * pred.size() + assign[g]] > kEps) drop[assign[g]] = 1;
      }
      std::vector<const Box*> kept;
      for (std::size_t p = 0; p < pred.size(); ++p) {
        if (drop[p]) {
          ++removed;
        } else {
          kept.push_back(pred[p]);
        }
      }
      pred.swap(kept);
    }
    detail::MotTimestep t;
    for (const Box* b : gt) {
      t.gt_ids.push_back(gt_ids.emplace(b->track_id, static_cast<int>(gt_ids.size())).first->second);
    }
    for (const Box* b : pred) {
      t.pred_ids.push_back(pred_ids.emplace(b->track_id, static_cast<int>(pred_ids.size())).first->second);
    }
    t.sim.resize(gt.size() * pred.size());
    for (std::size_t g = 0; g < gt.size(); ++g) {
      for (std::size_t p = 0; p < pred.size(); ++p) t.sim[g * pred.size() + p] = motSimilarity(*gt[g], *pred[p], options);
    }
    seq.num_gt_dets += static_cast<int>(gt.size());
    seq.num_pred_dets += static_cast<int>(pred.size());
    seq.steps.push_back(std::move(t));
  }
  seq.num_gt_ids = static_cast<int>(gt_ids.size());
  seq.num_pred_ids = static_cast<int>(pred_ids.size());
  num_pred_tracks += seq.num_pred_ids;
  return seq;
}

}  // namespace

MotResult evaluateMot(const std::vector<EvalFrame>& frames, const MotOptions& options) {
  MotResult result;
  // Sequences: runs of consecutive frames with the same sequence name.
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (ranges.empty() || frames[i].sequence != frames[ranges.back().first].sequence) ranges.push_back({i, i});
    ranges.back().second = i + 1;
  }
  result.num_sequences = ranges.size();
  result.classes.resize(options.classes.size());
  std::vector<std::size_t> removed(options.classes.size(), 0);
  detail::parallelFor(options.classes.size(), options.threads, [&](std::size_t c) {
    MotClassResult& cr = result.classes[c];
    cr.cls = options.classes[c];
    ClearSums clear;
    detail::HotaSums hota;
    for (const auto& [begin, end] : ranges) {
      const detail::MotSequence seq = prepare(frames, begin, end, cr.cls, options, removed[c], cr.num_pred_tracks);
      cr.num_pred += seq.num_pred_dets;
      accumulateClear(seq, options.threshold, clear);
      detail::accumulateHota(seq, hota);
    }
    cr.clear = finishClear(clear);
    cr.hota = detail::finishHota(hota);
  });
  for (std::size_t r : removed) result.removed_on_ignore += r;
  return result;
}

}  // namespace eval
}  // namespace ret3d
