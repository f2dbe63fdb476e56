// HOTA (Luiten et al., "HOTA: A Higher Order Metric for Evaluating Multi-Object Tracking", IJCV 2021), computed as
// TrackEval's hota.py does, so the numbers compare with published ones.
#include <algorithm>
#include <cmath>

#include "assignment.h"
#include "mot_sequence.h"

namespace ret3d {
namespace eval {
namespace detail {

namespace {
constexpr double kEps = 2.220446049250313e-16;  // numpy's float eps, as TrackEval compares with it
double alphaAt(int a) { return 0.05 * (a + 1); }
}  // namespace

namespace {

// Pass 1: the global alignment between ground-truth and predicted ids, from similarity normalised per timestep (a
// soft Jaccard count), with each id's number of detections.
struct IdAlignment {
  std::vector<double> alignment;  // gt id x pred id
  std::vector<double> gt_count, pred_count;
};

IdAlignment alignIds(const MotSequence& seq) {
  const int ng = seq.num_gt_ids, np = seq.num_pred_ids;
  std::vector<double> potential(static_cast<std::size_t>(ng) * np, 0.0);
  IdAlignment al;
  al.gt_count.assign(ng, 0.0);
  al.pred_count.assign(np, 0.0);
  for (const MotTimestep& t : seq.steps) {
    const std::size_t nr = t.gt_ids.size(), nc = t.pred_ids.size();
    std::vector<double> row_sum(nr, 0.0), col_sum(nc, 0.0);
    for (std::size_t g = 0; g < nr; ++g) {
      for (std::size_t p = 0; p < nc; ++p) {
        row_sum[g] += t.at(g, p);
        col_sum[p] += t.at(g, p);
      }
    }
    for (std::size_t g = 0; g < nr; ++g) {
      for (std::size_t p = 0; p < nc; ++p) {
        const double denom = row_sum[g] + col_sum[p] - t.at(g, p);
        if (denom > kEps) potential[static_cast<std::size_t>(t.gt_ids[g]) * np + t.pred_ids[p]] += t.at(g, p) / denom;
      }
    }
    for (int id : t.gt_ids) al.gt_count[id] += 1;
    for (int id : t.pred_ids) al.pred_count[id] += 1;
  }
  al.alignment.resize(potential.size());
  for (int g = 0; g < ng; ++g) {
    for (int p = 0; p < np; ++p) {
      const std::size_t k = static_cast<std::size_t>(g) * np + p;
      al.alignment[k] = potential[k] / (al.gt_count[g] + al.pred_count[p] - potential[k]);
    }
  }
  return al;
}

// Pass 2's counts at each alpha: matched id pairs (gt id x pred id), true positives, summed localisation.
struct AlphaMatches {
  std::array<std::vector<double>, kHotaAlphas> matches;
  std::array<double, kHotaAlphas> tp{}, loca{};
};

// Pass 2: per timestep, match by alignment x similarity, then count at each alpha (false positives and negatives
// straight into sums).
AlphaMatches matchTimesteps(const MotSequence& seq, const IdAlignment& al, HotaSums& sums) {
  const int np = seq.num_pred_ids;
  AlphaMatches am;
  for (auto& m : am.matches) m.assign(al.alignment.size(), 0.0);
  for (const MotTimestep& t : seq.steps) {
    const std::size_t nr = t.gt_ids.size(), nc = t.pred_ids.size();
    if (nr == 0 || nc == 0) {
      for (int a = 0; a < kHotaAlphas; ++a) {
        sums.fp[a] += nc;
        sums.fn[a] += nr;
      }
      continue;
    }
    std::vector<double> score(nr * nc);
    for (std::size_t g = 0; g < nr; ++g) {
      for (std::size_t p = 0; p < nc; ++p) {
        score[g * nc + p] = al.alignment[static_cast<std::size_t>(t.gt_ids[g]) * np + t.pred_ids[p]] * t.at(g, p);
      }
    }
    const std::vector<int> assign = maximiseAssignment(score, static_cast<int>(nr), static_cast<int>(nc));
    for (int a = 0; a < kHotaAlphas; ++a) {
      int n_match = 0;
      for (std::size_t g = 0; g < nr; ++g) {
        if (assign[g] < 0) continue;
        const double s = t.at(g, assign[g]);
        if (s < alphaAt(a) - kEps) continue;
        ++n_match;
        am.loca[a] += s;
        am.matches[a][static_cast<std::size_t>(t.gt_ids[g]) * np + t.pred_ids[assign[g]]] += 1;
      }
      am.tp[a] += n_match;
      sums.fn[a] += nr - n_match;
      sums.fp[a] += nc - n_match;
    }
  }
  return am;
}

}  // namespace

void accumulateHota(const MotSequence& seq, HotaSums& sums) {
  if (seq.num_pred_dets == 0) {
    for (int a = 0; a < kHotaAlphas; ++a) sums.fn[a] += seq.num_gt_dets;
    return;
  }
  if (seq.num_gt_dets == 0) {
    for (int a = 0; a < kHotaAlphas; ++a) sums.fp[a] += seq.num_pred_dets;
    return;
  }
  const int ng = seq.num_gt_ids, np = seq.num_pred_ids;
  const IdAlignment al = alignIds(seq);
  const AlphaMatches am = matchTimesteps(seq, al, sums);
  for (int a = 0; a < kHotaAlphas; ++a) {
    double assa = 0, assre = 0, asspr = 0;
    for (int g = 0; g < ng; ++g) {
      for (int p = 0; p < np; ++p) {
        const double m = am.matches[a][static_cast<std::size_t>(g) * np + p];
        if (m == 0) continue;
        assa += m * m / std::max(1.0, al.gt_count[g] + al.pred_count[p] - m);
        assre += m * m / std::max(1.0, al.gt_count[g]);
        asspr += m * m / std::max(1.0, al.pred_count[p]);
      }
    }
    // The sequence's AssA is the sum over TP / TP; weighted by TP for the combination that is the sum itself.
    sums.tp[a] += am.tp[a];
    sums.assa_w[a] += assa;
    sums.assre_w[a] += assre;
    sums.asspr_w[a] += asspr;
    sums.loca_w[a] += am.loca[a];
  }
}

Hota finishHota(const HotaSums& s) {
  Hota h;
  for (int a = 0; a < kHotaAlphas; ++a) {
    const double tp = s.tp[a], fn = s.fn[a], fp = s.fp[a];
    const double deta = tp / std::max(1.0, tp + fn + fp);
    const double assa = s.assa_w[a] / std::max(1.0, tp);
    h.deta_alpha[a] = 100.0 * deta;
    h.assa_alpha[a] = 100.0 * assa;
    h.hota_alpha[a] = 100.0 * std::sqrt(deta * assa);
    h.hota += h.hota_alpha[a];
    h.deta += h.deta_alpha[a];
    h.assa += h.assa_alpha[a];
    h.detre += 100.0 * tp / std::max(1.0, tp + fn);
    h.detpr += 100.0 * tp / std::max(1.0, tp + fp);
    h.assre += 100.0 * s.assre_w[a] / std::max(1.0, tp);
    h.asspr += 100.0 * s.asspr_w[a] / std::max(1.0, tp);
    h.loca += 100.0 * std::max(1e-10, s.loca_w[a]) / std::max(1e-10, tp);
  }
  for (double* v : {&h.hota, &h.deta, &h.assa, &h.detre, &h.detpr, &h.assre, &h.asspr, &h.loca}) *v /= kHotaAlphas;
  return h;
}

}  // namespace detail
}  // namespace eval
}  // namespace ret3d
