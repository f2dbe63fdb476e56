#include "ret3d/eval/id_stability.h"

#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "assignment.h"
#include "ret3d/eval/mot_metrics.h"

namespace ret3d {
namespace eval {

namespace {

using TrackKey = std::pair<std::string, std::uint32_t>;  // (sequence, id): ids are per sequence

// One class over every frame.
IdStabilityCounts countClass(const std::vector<EvalFrame>& frames, ObjectClass cls,
                             const IdStabilityOptions& options) {
  MotOptions similarity;
  similarity.similarity = MotSimilarity::CenterDistance;
  similarity.zero_distance = options.max_center_distance;

  // Per ground-truth track: how often each output id covered it.
  std::map<TrackKey, std::map<std::uint32_t, std::size_t>> covered_by;
  std::set<TrackKey> output_ids;
  IdStabilityCounts c;
  for (const EvalFrame& f : frames) {
    std::vector<const Box*> gt, pred;
    for (std::size_t i = 0; i < f.gt_boxes.size(); ++i) {
      const Box& b = f.gt_boxes[i];
      if (b.label != cls || (i < f.gt_ignore.size() && f.gt_ignore[i])) continue;
      if (b.track_id == 0) {
        throw std::invalid_argument("id stability: a ground-truth " + std::string(className(cls)) + " in frame " +
                                    std::to_string(f.frame) + (f.sequence.empty() ? "" : " of sequence " + f.sequence) +
                                    " has no track id");
      }
      gt.push_back(&b);
    }
    for (const Box& b : f.pred_boxes) {
      if (b.label == cls) pred.push_back(&b);
    }
    c.gt_track_frames += gt.size();
    if (gt.empty() || pred.empty()) continue;
    std::vector<double> score(gt.size() * pred.size());
    for (std::size_t g = 0; g < gt.size(); ++g) {
      for (std::size_t p = 0; p < pred.size(); ++p) {
        score[g * pred.size() + p] = motSimilarity(*gt[g], *pred[p], similarity);
      }
    }
    const auto assign = detail::maximiseAssignment(score, static_cast<int>(gt.size()), static_cast<int>(pred.size()));
    for (std::size_t g = 0; g < gt.size(); ++g) {
      if (assign[g] < 0) continue;
      const Box& p = *pred[assign[g]];
      // The assignment pairs every row it can; only pairs within the distance are matches.
      if ((gt[g]->center() - p.center()).norm() > options.max_center_distance) continue;
      ++covered_by[{f.sequence, gt[g]->track_id}][p.track_id];
      if (p.track_id != 0) output_ids.insert({f.sequence, p.track_id});
    }
  }
  for (const auto& [track, ids] : covered_by) {
    std::size_t most = 0;
    for (const auto& [id, n] : ids) {
      c.matched += n;
      if (id != 0 && n > most) most = n;
    }
    c.stable += most;
    ++c.gt_tracks;
  }
  c.output_ids = output_ids.size();
  return c;
}

void add(IdStabilityCounts& sum, const IdStabilityCounts& c) {
  sum.gt_track_frames += c.gt_track_frames;
  sum.matched += c.matched;
  sum.stable += c.stable;
  sum.gt_tracks += c.gt_tracks;
  sum.output_ids += c.output_ids;
}

}  // namespace

IdStabilityResult evaluateIdStability(const std::vector<EvalFrame>& frames, const IdStabilityOptions& options) {
  if (!(options.max_center_distance > 0)) {
    throw std::invalid_argument("id stability: max_center_distance must be positive, got " +
                                std::to_string(options.max_center_distance));
  }
  IdStabilityResult result;
  for (ObjectClass cls : options.classes) {
    IdStabilityClassResult r;
    r.cls = cls;
    r.counts = countClass(frames, cls, options);
    add(result.all, r.counts);
    result.classes.push_back(r);
  }
  return result;
}

}  // namespace eval
}  // namespace ret3d
