#include "ret3d/detector/point_refine.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "ret3d/core/geometry.h"

namespace ret3d {

void PointRefineOptions::validate() const {
  auto fail = [](const std::string& field, const std::string& what) {
    throw std::invalid_argument("point_refine." + field + " " + what);
  };
  for (ObjectClass c : faces)
    if (c == ObjectClass::Unknown) fail("faces", "must name Car, Pedestrian or Cyclist");
  for (const auto& [c, offset] : centroid) {
    if (c == ObjectClass::Unknown) fail("centroid", "must name Car, Pedestrian or Cyclist");
    if (!(std::abs(offset) < 2)) fail("centroid", "offsets must lie in (-2, 2) m");
    if (std::find(faces.begin(), faces.end(), c) != faces.end())
      fail("centroid", std::string("lists ") + className(c) + ", which faces refines already");
  }
  if (!(centroid_margin >= 0 && centroid_margin < 5)) fail("centroid_margin", "must lie in [0, 5) m");
  if (!(vertical_resolution_deg >= 0 && vertical_resolution_deg < 10))
    fail("vertical_resolution_deg", "must lie in [0, 10) deg");
  if (!(quantile > 0 && quantile <= 1)) fail("quantile", "must lie in (0, 1]");
  if (!(surface_gap >= 0 && surface_gap < 1)) fail("surface_gap", "must lie in [0, 1) m");
  if (!(margin >= 0 && margin < 5)) fail("margin", "must lie in [0, 5) m");
  if (!(ground_clearance >= 0 && ground_clearance < 5)) fail("ground_clearance", "must lie in [0, 5) m");
  if (!(max_shift >= 0 && max_shift < 5)) fail("max_shift", "must lie in [0, 5) m");
  if (min_points < 1) fail("min_points", "must be >= 1");
  if (!(heading_search_deg >= 0 && heading_search_deg < 45)) fail("heading_search_deg", "must lie in [0, 45) deg");
  if (heading_any && !(heading_search_deg > 0)) fail("heading_any", "needs heading_search_deg > 0");
  if (!(heading_step_deg > 0 && heading_step_deg <= 10)) fail("heading_step_deg", "must lie in (0, 10] deg");
  if (heading_min_points < 3) fail("heading_min_points", "must be >= 3");
  if (!(clear_above_gap >= 0 && clear_above_gap < 5)) fail("clear_above_gap", "must lie in [0, 5) m");
  if (!(clear_above_height > clear_above_gap && clear_above_height < 10))
    fail("clear_above_height", "must lie in (clear_above_gap, 10) m");
  if (clear_above_max_returns < 0) fail("clear_above_max_returns", "must be >= 0");
  for (ObjectClass c : clear_above)
    if (c == ObjectClass::Unknown) fail("clear_above", "must name Car, Pedestrian or Cyclist");
  for (const auto& [c, w] : score_calibration) {
    if (c == ObjectClass::Unknown) fail("score_calibration", "must name Car, Pedestrian or Cyclist");
    if (w.size() != kCalibrationFeatures)
      fail("score_calibration", std::string("needs ") + std::to_string(kCalibrationFeatures) + " weights for " +
                                    className(c) + ", not " + std::to_string(w.size()));
    for (double v : w)
      if (!std::isfinite(v)) fail("score_calibration", std::string("weights of ") + className(c) + " must be finite");
  }
}

namespace {

// The returns between heights z0 and z1 binned in square cells over the area the boxes cover (a counting sort), so
// that each box visits only the returns near it (ground returns, most of a scan, are left out by z0).
class CellIndex {
 public:
  CellIndex(const PointCloud& cloud, double x0, double y0, double x1, double y1, double z0, double z1, double cell)
      : x0_(x0), y0_(y0), cell_(cell) {
    nx_ = std::max(1, static_cast<int>(std::ceil((x1 - x0) / cell)));
    ny_ = std::max(1, static_cast<int>(std::ceil((y1 - y0) / cell)));
    start_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
    std::vector<int> cell_of(cloud.size(), -1);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Point& p = cloud.points[i];
      const int cx = cellX(p.x), cy = cellY(p.y);
      if (cx < 0 || cy < 0 || cx >= nx_ || cy >= ny_ || !(p.z > z0 && p.z < z1)) continue;
      cell_of[i] = cy * nx_ + cx;
      ++start_[static_cast<std::size_t>(cell_of[i]) + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    order_.resize(start_.back());
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < cloud.size(); ++i)
      if (cell_of[i] >= 0) order_[fill[static_cast<std::size_t>(cell_of[i])]++] = i;
  }

  // Calls f(point index) for the returns in the cells overlapping [x - r, x + r] x [y - r, y + r].
  template <typename F>
  void visit(double x, double y, double r, F&& f) const {
    const int cx0 = std::max(0, cellX(x - r)), cx1 = std::min(nx_ - 1, cellX(x + r));
    const int cy0 = std::max(0, cellY(y - r)), cy1 = std::min(ny_ - 1, cellY(y + r));
    for (int cy = cy0; cy <= cy1; ++cy)
      for (int cx = cx0; cx <= cx1; ++cx) {
        const std::size_t c = static_cast<std::size_t>(cy) * nx_ + cx;
        for (std::size_t k = start_[c]; k < start_[c + 1]; ++k) f(order_[k]);
      }
  }

 private:
  int cellX(double x) const { return clampedCell((x - x0_) / cell_, nx_); }
  int cellY(double y) const { return clampedCell((y - y0_) / cell_, ny_); }
  // -1 below the grid (and for NaN), n above it: compared before the cast, as a NaN or huge coordinate does not fit
  // an int (UB; UBSan on PointRefine.LeavesOtherClassesSparseObjectsAndFarMovesAlone's NaN returns).
  static int clampedCell(double f, int n) {
    const double c = std::floor(f);
    return c >= 0 ? (c < n ? static_cast<int>(c) : n) : -1;
  }
  double x0_, y0_, cell_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::size_t> start_, order_;
};

double quantileOf(std::vector<double>* v, double q) {
  const auto k = static_cast<std::ptrdiff_t>(std::floor(q * static_cast<double>(v->size() - 1)));
  std::nth_element(v->begin(), v->begin() + k, v->end());
  return (*v)[static_cast<std::size_t>(k)];
}

// The returns of `b` (its footprint grown by `margin`, from ground_clearance above its bottom to z_top) in the box
// frame: u along the heading, v across, and z.
struct BoxReturns {
  std::vector<double> u, v, z;
  void collect(const PointCloud& cloud, const CellIndex& index, const Box& b, double margin, double clearance,
               double z_top) {
    u.clear(), v.clear(), z.clear();
    const double c = std::cos(b.yaw), s = std::sin(b.yaw);
    const double hl = 0.5 * b.length + margin, hw = 0.5 * b.width + margin;
    const double z_lo = b.bottom() + clearance;
    index.visit(b.x, b.y, std::hypot(hl, hw), [&](std::size_t i) {
      const Point& p = cloud.points[i];
      if (!(p.z > z_lo && p.z < z_top)) return;
      const double dx = p.x - b.x, dy = p.y - b.y;
      const double pu = dx * c + dy * s, pv = -dx * s + dy * c;
      if (std::abs(pu) >= hl || std::abs(pv) >= hw) return;
      u.push_back(pu), v.push_back(pv), z.push_back(p.z);
    });
  }
};

// The top from the highest returns (the bottom stays): the network's top clamped to what the returns allow.
void refineTop(const PointRefineOptions& o, std::vector<double>* z, Box* b) {
  if (z->empty()) return;
  const double bottom = b->bottom();
  const double highest = quantileOf(z, 0.995) + o.surface_gap;
  const double slack = std::hypot(b->x, b->y) * std::tan(o.vertical_resolution_deg * M_PI / 180.0);
  const double top = std::clamp(b->top(), highest, highest + slack);
  b->height = std::clamp(top - bottom, 0.5 * b->height, 1.5 * b->height);
  b->z = bottom + 0.5 * b->height;
}

// heading_any: 0 or a quarter turn, whichever makes the returns' extents (2 % - 98 % quantiles, less a surface
// allowance) along and across the fitted heading fit within the network's length and width; when both fit, or
// neither does better, the one nearer the network's heading (0 when the fit stayed within 45 deg of it).
double lengthAxisTurn(const std::vector<double>& x, const std::vector<double>& y, double yaw, const Box& b) {
  constexpr double kAllowance = 0.15;  // m: range noise and mirrors beyond the box the labeller drew
  const double c = std::cos(yaw), s = std::sin(yaw);
  std::vector<double> along(x.size()), across(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) along[i] = x[i] * c + y[i] * s, across[i] = -x[i] * s + y[i] * c;
  auto extent = [](std::vector<double>* v) { return quantileOf(v, 0.98) - quantileOf(v, 0.02) - kAllowance; };
  const double e_along = extent(&along), e_across = extent(&across);
  auto overflow = [&](double e_length, double e_width) {
    return std::max(0.0, e_length - b.length) + std::max(0.0, e_width - b.width);
  };
  const double keep = overflow(e_along, e_across), turn = overflow(e_across, e_along);
  return turn + 1e-9 < keep ? 0.5 * M_PI : 0.0;
}

// The heading that best fits the outline of the returns within half a length (plus the margin) of the centre, from
// the network's heading +- heading_search_deg (see heading_search_deg in the header).
double fitHeading(const PointCloud& cloud, const CellIndex& index, const PointRefineOptions& o, const Box& b) {
  constexpr std::size_t kMaxReturns = 400;  // more are thinned evenly: the score needs the outline, not every return
  constexpr double kCloseness = 0.02;       // d0 of the criterion (m): about the returns' range noise
  const double radius = 0.5 * b.length + o.margin, z_lo = b.bottom() + o.ground_clearance;
  const double z_hi = b.top() + 2 * o.margin;
  std::vector<double> x, y;
  index.visit(b.x, b.y, radius, [&](std::size_t i) {
    const Point& p = cloud.points[i];
    const double dx = p.x - b.x, dy = p.y - b.y;
    if (p.z > z_lo && p.z < z_hi && dx * dx + dy * dy < radius * radius) x.push_back(dx), y.push_back(dy);
  });
  if (static_cast<int>(x.size()) < o.heading_min_points) return b.yaw;
  const std::size_t stride = (x.size() + kMaxReturns - 1) / kMaxReturns;
  std::size_t n = 0;
  for (std::size_t i = 0; i < x.size(); i += stride, ++n) x[n] = x[i], y[n] = y[i];
  x.resize(n), y.resize(n);

  std::vector<double> c1(n), c2(n);
  // Distance of each return to the face of its axis that the returns hug (the one nearer them in sum of squares).
  auto toFace = [&](std::vector<double>* c) {
    const auto [lo, hi] = std::minmax_element(c->begin(), c->end());
    const double cmin = *lo, cmax = *hi;
    double to_min = 0, to_max = 0;
    for (double v : *c) to_min += (v - cmin) * (v - cmin), to_max += (cmax - v) * (cmax - v);
    for (double& v : *c) v = to_min <= to_max ? v - cmin : cmax - v;
  };
  const double step = o.heading_step_deg * M_PI / 180.0;
  // heading_any: [-45, 45) deg around the network's covers every outline (it repeats each quarter turn).
  const int steps = static_cast<int>(std::floor((o.heading_any ? 45.0 : o.heading_search_deg) / o.heading_step_deg));
  const int last = o.heading_any ? steps - 1 : steps;
  // The best score's first run of steps: every return within d0 of a face scores the same, so the score is flat
  // over a few steps around the true heading, whose middle is taken.
  int best_lo = 0, best_hi = 0;
  double best_score = -1;
  for (int k = -steps; k <= last; ++k) {
    const double yaw = b.yaw + k * step, c = std::cos(yaw), s = std::sin(yaw);
    for (std::size_t i = 0; i < n; ++i) c1[i] = x[i] * c + y[i] * s, c2[i] = -x[i] * s + y[i] * c;
    toFace(&c1), toFace(&c2);
    double score = 0;
    for (std::size_t i = 0; i < n; ++i) score += 1.0 / std::max(std::min(c1[i], c2[i]), kCloseness);
    if (score > best_score * (1 + 1e-9))
      best_score = score, best_lo = best_hi = k;
    else if (score >= best_score * (1 - 1e-9) && k == best_hi + 1)
      best_hi = k;
  }
  const double fitted = b.yaw + 0.5 * (best_lo + best_hi) * step;
  if (!o.heading_any) return wrapAngle(fitted);
  return wrapAngle(fitted + lengthAxisTurn(x, y, fitted, b));
}

bool refineFaces(const PointCloud& cloud, const CellIndex& index, const PointRefineOptions& o, BoxReturns* r,
                 Box* b) {
  if (o.heading_search_deg > 0) b->yaw = fitHeading(cloud, index, o, *b);
  r->collect(cloud, index, *b, o.margin, o.ground_clearance, b->top() + 2 * o.margin);
  if (static_cast<int>(r->u.size()) < o.min_points) return false;
  const double c = std::cos(b->yaw), s = std::sin(b->yaw);
  // The sensor (the origin) in the box frame: a face is visible when the sensor lies beyond it.
  const double u_sensor = -(b->x * c + b->y * s), v_sensor = b->x * s - b->y * c;
  // Along one box axis: the move of the centre, and (grow) the size the returns need.
  auto shift = [&](std::vector<double>* coord, double sensor, double* size) {
    const double half_size = 0.5 * *size;
    if (std::abs(sensor) <= half_size) {
      // Both faces hidden: the visible perpendicular face spans this axis, so its returns centre the box.
      if (!o.hidden_midpoint) return 0.0;
      const double lo = quantileOf(coord, 1 - o.quantile), hi = quantileOf(coord, o.quantile);
      return std::clamp(0.5 * (lo + hi), -o.max_shift, o.max_shift);
    }
    const double sign = sensor > 0 ? 1.0 : -1.0;
    for (double& x : *coord) x *= sign;
    const double face = quantileOf(coord, o.quantile);
    const double d = std::clamp(sign * (face + o.surface_gap - half_size), -o.max_shift, o.max_shift);
    if (!o.grow) return d;
    // The far face must hold the returns seen beyond it (a side seen along its whole length).
    const double far = quantileOf(coord, 1 - o.quantile) - o.surface_gap;  // toward the sensor = positive
    const double near_face = sign * d + half_size;
    const double need = near_face - far;
    if (need > *size && need < *size + o.max_shift) {
      const double grow = need - *size;
      *size = need;
      return d - sign * 0.5 * grow;
    }
    return d;
  };
  const double du = shift(&r->u, u_sensor, &b->length), dv = shift(&r->v, v_sensor, &b->width);
  b->x += du * c - dv * s;
  b->y += du * s + dv * c;
  if (o.height) refineTop(o, &r->z, b);
  return true;
}

bool refineCentroid(const PointCloud& cloud, const CellIndex& index, const PointRefineOptions& o, double offset,
                    BoxReturns* r, Box* b) {
  const double x0 = b->x, y0 = b->y;
  bool moved = false;
  for (int iteration = 0; iteration < 2; ++iteration) {
    r->collect(cloud, index, *b, o.centroid_margin, o.ground_clearance, b->top());
    if (static_cast<int>(r->u.size()) < o.min_points) break;
    double mu = 0, mv = 0;
    for (std::size_t i = 0; i < r->u.size(); ++i) mu += r->u[i], mv += r->v[i];
    mu /= static_cast<double>(r->u.size()), mv /= static_cast<double>(r->u.size());
    const double c = std::cos(b->yaw), s = std::sin(b->yaw);
    const double mx = b->x + mu * c - mv * s, my = b->y + mu * s + mv * c, range = std::hypot(mx, my);
    if (range < 1e-3) break;
    b->x = mx + offset * mx / range;
    b->y = my + offset * my / range;
    moved = true;
  }
  const double d = std::hypot(b->x - x0, b->y - y0);
  if (d > o.max_shift) {
    b->x = x0 + (b->x - x0) * o.max_shift / d;
    b->y = y0 + (b->y - y0) * o.max_shift / d;
  }
  if (moved && o.centroid_height) {
    r->collect(cloud, index, *b, o.centroid_margin, o.ground_clearance, b->top() + 2 * o.centroid_margin);
    refineTop(o, &r->z, b);
  }
  return moved;
}

bool needsClearAbove(const PointRefineOptions& o, const Box& b) {
  return std::find(o.clear_above.begin(), o.clear_above.end(), b.label) != o.clear_above.end();
}

// The calibrated score of box `b` from its returns `r` (score_calibration in the header).
double calibratedScore(const std::vector<double>& w, const Box& b, BoxReturns* r) {
  const std::size_t n = r->u.size();
  double residual = PointRefineOptions::kMaxResidual;
  if (n >= 3) {
    // Each return's distance to the nearer face of the box (reusing z as scratch), then their median.
    const double hl = 0.5 * b.length, hw = 0.5 * b.width;
    for (std::size_t i = 0; i < n; ++i)
      r->z[i] = std::min(std::abs(std::abs(r->u[i]) - hl), std::abs(std::abs(r->v[i]) - hw));
    residual = std::min(residual, quantileOf(&r->z, 0.5));
  }
  const double s = std::clamp(static_cast<double>(b.score), 1e-4, 1 - 1e-4), logit = std::log(s / (1 - s));
  const double log_n = std::log1p(static_cast<double>(n)), range = std::hypot(b.x, b.y) / 40.0;
  const double aspect = std::abs(std::sin(b.yaw - std::atan2(b.y, b.x)));
  const double f[PointRefineOptions::kCalibrationFeatures] = {
      1, logit, log_n, range, log_n * range, logit * log_n, aspect, aspect * aspect, residual};
  double z = 0;
  for (std::size_t k = 0; k < PointRefineOptions::kCalibrationFeatures; ++k) z += w[k] * f[k];
  return 1.0 / (1.0 + std::exp(-z));
}

}  // namespace

std::size_t refineBoxesFromPoints(const PointCloud& cloud, std::vector<Box>* boxes, const PointRefineOptions& o) {
  auto calibration = [&](const Box& b) -> const std::vector<double>* {
    for (const auto& [c, w] : o.score_calibration)
      if (c == b.label) return &w;
    return nullptr;
  };
  // The face classes' mode (1), the centroid offset (2) of a box, or only its score calibrated or the space above it
  // checked (3); 0 = none.
  auto mode = [&](const Box& b, double* offset) {
    if (!(b.length > 0 && b.width > 0 && b.height > 0 && std::isfinite(b.x) && std::isfinite(b.y) &&
          std::isfinite(b.z) && std::isfinite(b.yaw)))
      return 0;
    if (std::find(o.faces.begin(), o.faces.end(), b.label) != o.faces.end()) return 1;
    for (const auto& [c, off] : o.centroid)
      if (c == b.label) return *offset = off, 2;
    return calibration(b) || needsClearAbove(o, b) ? 3 : 0;
  };
  double x0 = 1e300, y0 = 1e300, z0 = 1e300, x1 = -1e300, y1 = -1e300, z1 = -1e300, offset = 0;
  for (const Box& b : *boxes) {
    if (!mode(b, &offset)) continue;
    const double margin = std::max(o.margin, o.centroid_margin);
    const double r = 0.5 * std::hypot(b.length, b.width) + margin + o.max_shift;
    x0 = std::min(x0, b.x - r), y0 = std::min(y0, b.y - r), z0 = std::min(z0, b.bottom() + o.ground_clearance);
    x1 = std::max(x1, b.x + r), y1 = std::max(y1, b.y + r), z1 = std::max(z1, b.top() + 2 * margin);
    if (needsClearAbove(o, b)) z1 = std::max(z1, b.top() + o.max_shift + o.clear_above_height);
  }
  if (x0 > x1 || cloud.empty()) return 0;
  const CellIndex index(cloud, x0, y0, x1 + 1e-6, y1 + 1e-6, z0, z1, 1.0);

  std::size_t changed = 0;
  BoxReturns returns;
  for (Box& b : *boxes) {
    const int m = mode(b, &offset);
    if (m == 1 && refineFaces(cloud, index, o, &returns, &b)) ++changed;
    if (m == 2 && refineCentroid(cloud, index, o, offset, &returns, &b)) ++changed;
    if (const auto* w = m ? calibration(b) : nullptr) {
      returns.collect(cloud, index, b, o.margin, o.ground_clearance, b.top() + o.margin);
      b.score = static_cast<float>(calibratedScore(*w, b, &returns));
    }
  }
  const auto covered = std::remove_if(boxes->begin(), boxes->end(), [&](const Box& b) {
    if (!needsClearAbove(o, b) || mode(b, &offset) == 0) return false;
    returns.collect(cloud, index, b, 0.0, b.height + o.clear_above_gap, b.top() + o.clear_above_height);
    return static_cast<int>(returns.u.size()) > o.clear_above_max_returns;
  });
  changed += static_cast<std::size_t>(boxes->end() - covered);
  boxes->erase(covered, boxes->end());
  return changed;
}

std::size_t headingFromVelocity(std::vector<Box>* boxes, const std::vector<std::pair<ObjectClass, double>>& min_speed) {
  std::size_t changed = 0;
  for (Box& b : *boxes)
    for (const auto& [c, speed] : min_speed)
      if (c == b.label && std::hypot(b.vx, b.vy) >= speed && std::isfinite(b.vx) && std::isfinite(b.vy)) {
        b.yaw = std::atan2(b.vy, b.vx);
        ++changed;
      }
  return changed;
}

}  // namespace ret3d
