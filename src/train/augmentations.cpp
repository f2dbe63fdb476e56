#include "ret3d/train/augmentations.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/core/log.h"
#include "ret3d/core/progress.h"
#include "ret3d/core/transform.h"

namespace ret3d {

namespace {

constexpr char kGtMagic[] = "RET3DGTDB1";
constexpr double kFarRange = 80.0;  // the HDL-64E's maximum range in the KITTI scans
// Where an object's returns were in the previous sweep: its box moved back by its velocity over one sweep of a 10 Hz
// sensor (the cut region's margin absorbs other rates).
constexpr double kSweepDt = 0.1;

// Keeps the points (and their time and ring) for which keep(point) holds.
template <typename Pred>
void keepPoints(PointCloud* cloud, Pred keep) {
  const bool extras = cloud->hasTime() || cloud->hasRing();
  PointCloud out;
  out.points.reserve(cloud->size());
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (!keep(i, cloud->points[i])) continue;
    out.push_back(cloud->points[i], cloud->hasTime() ? cloud->time[i] : 0.0f, cloud->hasRing() ? cloud->ring[i] : 0,
                  extras);
  }
  *cloud = std::move(out);
}

void addPoint(PointCloud* cloud, const Point& p) {
  cloud->push_back(p, 0.0f, 0, cloud->hasTime() || cloud->hasRing());
}

double range(const Point& p) { return std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z); }

Point rotatedZ(const Point& p, double c, double s) {
  Point q = p;
  q.x = static_cast<float>(c * p.x - s * p.y);
  q.y = static_cast<float>(s * p.x + c * p.y);
  return q;
}

// Moves the boxes that lost their points (below `min_points` now and fewer than before) to the ignore list.
void ignoreEmptied(DetectorSample* s, const std::vector<std::uint32_t>& before, int min_points) {
  const auto after = countPointsInBoxes(s->boxes, s->current);
  const bool per_box = s->velocity_valid.size() == s->boxes.size();
  std::vector<Box> boxes;
  std::vector<bool> valid;
  for (std::size_t i = 0; i < s->boxes.size(); ++i) {
    if (static_cast<int>(after[i]) < min_points && after[i] < before[i]) {
      s->ignore.push_back(s->boxes[i]);
      continue;
    }
    boxes.push_back(s->boxes[i]);
    if (per_box) valid.push_back(s->velocity_valid[i]);
  }
  s->boxes = std::move(boxes);
  if (per_box) s->velocity_valid = std::move(valid);
}

}  // namespace

GtRegion::GtRegion(const Box& b, const GtDatabaseOptions& o)
    : x_(b.x), y_(b.y), cos_(std::cos(b.yaw)), sin_(std::sin(b.yaw)), half_length_(0.5 * b.length + o.grow),
      half_width_(0.5 * b.width + o.grow), z_min_(b.bottom() + o.ground_margin), z_max_(b.top() + o.grow) {}

bool GtRegion::contains(const Point& p) const {
  if (p.z < z_min_ || p.z > z_max_) return false;
  const double dx = p.x - x_, dy = p.y - y_;
  return std::abs(cos_ * dx + sin_ * dy) <= half_length_ && std::abs(-sin_ * dx + cos_ * dy) <= half_width_;
}

std::vector<GtObject> buildGtDatabase(const DetectorDataset& data, const GtDatabaseOptions& o) {
  std::vector<GtObject> out;
  ProgressBar bar("gt database", data.size());
  for (std::size_t i = 0; i < data.size(); ++i) {
    const DetectorSample s = data.load(i);
    for (const Box& b : s.boxes) {
      GtObject g;
      g.box = b;
      const GtRegion region(b, o);
      for (const Point& p : s.current.points)
        if (region.contains(p)) g.points.push_back(p);
      if (static_cast<int>(g.points.size()) < o.min_points) continue;
      g.box.num_points = static_cast<std::uint32_t>(g.points.size());
      g.box.vx = g.box.vy = 0;
      g.box.track_id = 0;
      out.push_back(std::move(g));
    }
    bar.tick(1, std::to_string(out.size()) + " objects");
  }
  bar.finish();
  return out;
}

void writeGtDatabase(const std::string& path, const std::vector<GtObject>& objects) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(path + ": cannot write the ground-truth database");
  f.write(kGtMagic, sizeof(kGtMagic) - 1);
  const std::uint64_t n = objects.size();
  f.write(reinterpret_cast<const char*>(&n), sizeof(n));
  for (const GtObject& g : objects) {
    const double box[7] = {g.box.x, g.box.y, g.box.z, g.box.length, g.box.width, g.box.height, g.box.yaw};
    f.write(reinterpret_cast<const char*>(box), sizeof(box));
    const std::uint8_t label = static_cast<std::uint8_t>(g.box.label);
    f.write(reinterpret_cast<const char*>(&label), 1);
    const std::uint32_t count = static_cast<std::uint32_t>(g.points.size());
    f.write(reinterpret_cast<const char*>(&count), sizeof(count));
    f.write(reinterpret_cast<const char*>(g.points.data()), static_cast<std::streamsize>(count * sizeof(Point)));
  }
  if (!f) throw std::runtime_error(path + ": writing the ground-truth database failed");
}

std::vector<GtObject> readGtDatabase(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(path + ": cannot open the ground-truth database (train.gt_database)");
  auto bad = [&](const std::string& why) {
    return std::runtime_error(path + ": not a ground-truth database of `ret3d train gtdb` (" + why + ")");
  };
  char magic[sizeof(kGtMagic) - 1];
  std::uint64_t n = 0;
  if (!f.read(magic, sizeof(magic)) || std::memcmp(magic, kGtMagic, sizeof(magic)) != 0) throw bad("header");
  if (!f.read(reinterpret_cast<char*>(&n), sizeof(n)) || n > 100000000) throw bad("object count");
  std::vector<GtObject> out(n);
  for (GtObject& g : out) {
    double box[7];
    std::uint8_t label = 0;
    std::uint32_t count = 0;
    if (!f.read(reinterpret_cast<char*>(box), sizeof(box)) || !f.read(reinterpret_cast<char*>(&label), 1) ||
        !f.read(reinterpret_cast<char*>(&count), sizeof(count)) || label > 3 || count > 10000000)
      throw bad("truncated or corrupt object");
    g.box.x = box[0], g.box.y = box[1], g.box.z = box[2];
    g.box.length = box[3], g.box.width = box[4], g.box.height = box[5], g.box.yaw = box[6];
    g.box.label = static_cast<ObjectClass>(label);
    g.box.num_points = count;
    g.points.resize(count);
    if (!f.read(reinterpret_cast<char*>(g.points.data()), static_cast<std::streamsize>(count * sizeof(Point))))
      throw bad("truncated points");
  }
  return out;
}

SensorAugmenter::SensorAugmenter(const SensorAugmentOptions& o) : o_(o) {
  if (o_.beam_subsample_probability > 0) beams_ = sim::loadSensorModel(o_.beam_sensor);
  if (o_.gtSamplingOn()) db_ = readGtDatabase(o_.gt_database);
  indexDatabase();
}

SensorAugmenter::SensorAugmenter(const SensorAugmentOptions& o, std::vector<double> beam_elevation_deg,
                                 std::vector<GtObject> db)
    : o_(o), db_(std::move(db)) {
  std::sort(beam_elevation_deg.begin(), beam_elevation_deg.end());
  beams_.elevation_deg = std::move(beam_elevation_deg);
  indexDatabase();
}

void SensorAugmenter::indexDatabase() {
  by_class_.assign(4, {});
  for (std::size_t i = 0; i < db_.size(); ++i) by_class_[static_cast<std::size_t>(db_[i].box.label) % 4].push_back(i);
}

void SensorAugmenter::apply(DetectorSample* s, std::mt19937* rng) const {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  auto chance = [&](double p) { return p > 0 && U(*rng) < p; };  // no draw while off
  if (o_.gtSamplingOn() && !db_.empty()) pasteObjects(s, rng);

  const bool drop = o_.ray_drop_max > 0 || o_.ray_drop_far > 0;
  const bool beams = chance(o_.beam_subsample_probability);
  if (drop || beams) {
    const auto before = countPointsInBoxes(s->boxes, s->current);
    if (beams) {
      const int k = o_.beam_subsample_keep_every;
      subsampleBeams(s, k, std::uniform_int_distribution<int>(0, k - 1)(*rng));
    }
    if (drop) {
      const double p = o_.ray_drop_min + (o_.ray_drop_max - o_.ray_drop_min) * U(*rng);
      dropRays(&s->current, p, o_.ray_drop_far, rng);
      if (s->has_previous) dropRays(&s->previous, p, o_.ray_drop_far, rng);
    }
    ignoreEmptied(s, before, o_.min_box_points);
  }

  if (o_.object_intensity_probability > 0) {
    const double lo = std::log(o_.object_intensity_gain_min), hi = std::log(o_.object_intensity_gain_max);
    for (const Box& b : s->boxes)  // pasted ones too (scaling changes points, never boxes)
      if (chance(o_.object_intensity_probability))
        scaleObjectIntensity(s, b, std::exp(lo + (hi - lo) * U(*rng)), kSweepDt);
  }
  if (o_.object_zero_probability > 0) {
    const auto& dark = o_.object_zero_classes;
    for (const Box& b : s->boxes)
      if (std::find(dark.begin(), dark.end(), b.label) != dark.end() && chance(o_.object_zero_probability))
        darkenObject(s, b, o_.object_zero_min + (o_.object_zero_max - o_.object_zero_min) * U(*rng), kSweepDt, rng);
  }
  if (chance(o_.intensity_jitter_probability)) {
    const double scale = o_.intensity_scale_min + (o_.intensity_scale_max - o_.intensity_scale_min) * U(*rng);
    const double gamma = o_.intensity_gamma_min + (o_.intensity_gamma_max - o_.intensity_gamma_min) * U(*rng);
    std::normal_distribution<double> noise(0.0, o_.intensity_noise_sigma);
    for (PointCloud* c : {&s->current, &s->previous})
      for (Point& p : c->points) {
        const double v = scale * std::pow(std::clamp<double>(p.intensity, 0.0, 1.0), gamma) +
                         (o_.intensity_noise_sigma > 0 ? noise(*rng) : 0.0);
        p.intensity = static_cast<float>(std::clamp(v, 0.0, 1.0));
      }
  }
  if (chance(o_.intensity_zero_probability)) {
    const double fraction = o_.intensity_zero_max * U(*rng);
    zeroIntensities(&s->current, fraction, rng);
    zeroIntensities(&s->previous, fraction, rng);
  }
  if (chance(o_.intensity_constant_probability))
    for (PointCloud* c : {&s->current, &s->previous})
      for (Point& p : c->points) p.intensity = static_cast<float>(o_.intensity_constant_value);

  if (chance(o_.previous_dropout_probability)) dropPreviousSweep(s);

  if (o_.pose_z_range > 0 || o_.pose_tilt_deg > 0) {
    const double tilt = o_.pose_tilt_deg * M_PI / 180.0;
    const double dz = (2 * U(*rng) - 1) * o_.pose_z_range;
    const double pitch = (2 * U(*rng) - 1) * tilt;
    const double roll = (2 * U(*rng) - 1) * tilt;
    jitterSensorPose(s, dz, pitch, roll);
  }
}

namespace {

// The objects pasted into one sweep, in order: each clears its region, then adds its points. Applied in one pass over
// the sweep (not one per object): a scene point goes when any region holds it, an object's point when a later
// object's region does, which is what clearing and adding one object after the other leaves.
struct Pasted {
  std::vector<GtRegion> cuts;
  std::vector<std::vector<Point>> points;
  void applyTo(PointCloud* cloud) const {
    if (cuts.empty()) return;
    keepPoints(cloud, [&](std::size_t, const Point& p) {
      return std::none_of(cuts.begin(), cuts.end(), [&](const GtRegion& r) { return r.contains(p); });
    });
    for (std::size_t j = 0; j < points.size(); ++j)
      for (const Point& p : points[j])
        if (std::none_of(cuts.begin() + static_cast<std::ptrdiff_t>(j) + 1, cuts.end(),
                         [&](const GtRegion& r) { return r.contains(p); }))
          addPoint(cloud, p);
  }
};

}  // namespace

void SensorAugmenter::pasteObjects(DetectorSample* s, std::mt19937* rng) const {
  const GtDatabaseOptions region;
  Pasted current, previous;
  std::uniform_real_distribution<double> U(0.0, 1.0);
  if (s->velocity_valid.size() != s->boxes.size()) s->velocity_valid.assign(s->boxes.size(), true);
  std::vector<Box> occupied = s->boxes;
  occupied.insert(occupied.end(), s->ignore.begin(), s->ignore.end());
  const Eigen::Isometry3d current_to_previous = s->prev_to_current.inverse();
  for (const auto& [cls, count] : o_.gt_sample_counts) {
    const auto& candidates = by_class_[static_cast<std::size_t>(cls) % 4];
    if (candidates.empty()) continue;
    std::uniform_int_distribution<std::size_t> pick(0, candidates.size() - 1);
    for (int k = 0; k < count; ++k) {
      const GtObject& g = db_[candidates[pick(*rng)]];
      // About the sensor's z axis: range, elevation and the side seen stay those the points were cast with.
      const double angle = (2 * U(*rng) - 1) * M_PI, c = std::cos(angle), sn = std::sin(angle);
      Box b = g.box;
      b.x = c * g.box.x - sn * g.box.y;
      b.y = sn * g.box.x + c * g.box.y;
      b.yaw = wrapAngle(g.box.yaw + angle);
      // At least the cut region's margin, so clearing the region never takes another object's returns.
      const double margin = std::max(o_.gt_sample_margin, region.grow);
      Box grown = b;
      grown.length += 2 * margin;
      grown.width += 2 * margin;
      bool free = true;
      for (const Box& other : occupied)
        if (bevIntersectionArea(grown, other) > 0) {
          free = false;
          break;
        }
      if (!free) continue;
      auto paste = [&](Pasted* into, const Box& at, const Eigen::Isometry3d& T) {
        into->cuts.emplace_back(at, region);
        into->points.emplace_back();
        for (const Point& p : g.points) {
          Point q = rotatedZ(p, c, sn);
          const Eigen::Vector3d v = T * Eigen::Vector3d(q.x, q.y, q.z);
          q.x = static_cast<float>(v.x()), q.y = static_cast<float>(v.y()), q.z = static_cast<float>(v.z());
          into->points.back().push_back(q);
        }
      };
      paste(&current, b, Eigen::Isometry3d::Identity());
      // Into the previous sweep at the same place in the world: a parked object, velocity zero.
      if (s->has_previous) paste(&previous, transformBox(b, current_to_previous), current_to_previous);
      b.vx = b.vy = 0;
      b.track_id = 0;
      s->boxes.push_back(b);
      s->velocity_valid.push_back(s->has_previous);
      occupied.push_back(b);
    }
  }
  current.applyTo(&s->current);
  if (s->has_previous) previous.applyTo(&s->previous);
}

void SensorAugmenter::subsampleBeams(DetectorSample* s, int keep_every, int offset) const {
  for (PointCloud* cloud : {&s->current, &s->previous}) {
    const bool ring = cloud->hasRing();
    keepPoints(cloud, [&](std::size_t i, const Point& p) {
      const int beam = ring ? cloud->ring[i]
                            : sim::nearestBeam(beams_, std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / M_PI);
      return beam >= 0 && beam % keep_every == offset;
    });
  }
}

void dropRays(PointCloud* cloud, double p, double far, std::mt19937* rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  keepPoints(cloud, [&](std::size_t, const Point& q) {
    const double drop = far > 0 ? p + far * std::min(1.0, range(q) / kFarRange) : p;
    return U(*rng) >= drop;
  });
}

void zeroIntensities(PointCloud* cloud, double fraction, std::mt19937* rng) {
  const std::size_t n = cloud->size();
  const std::size_t m = std::min(n, static_cast<std::size_t>(std::lround(fraction * n)));
  if (m == 0) return;
  // Weighted sampling without replacement (Efraimidis-Spirakis): the m largest keys log(u) / w.
  std::uniform_real_distribution<double> U(1e-12, 1.0);
  std::vector<std::pair<double, std::size_t>> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = {std::log(U(*rng)) / std::max(1.0, range(cloud->points[i])), i};
  std::nth_element(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(m), keys.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; k < m; ++k) cloud->points[keys[k].second].intensity = 0.0f;
}

namespace {

// Calls f on each return of `box` in both sweeps (in the previous one where the object was then); returns the number
// of current-sweep returns.
template <typename F>
std::size_t forObjectReturns(DetectorSample* s, const Box& box, double dt, F f) {
  const GtDatabaseOptions grow;
  std::size_t count = 0;
  const GtRegion now(box, grow);
  for (Point& p : s->current.points)
    if (now.contains(p)) f(&p), ++count;
  if (s->has_previous) {
    Box then = box;
    then.x -= box.vx * dt;
    then.y -= box.vy * dt;
    const GtRegion before(transformBox(then, s->prev_to_current.inverse()), grow);
    for (Point& p : s->previous.points)
      if (before.contains(p)) f(&p);
  }
  return count;
}

}  // namespace

std::size_t scaleObjectIntensity(DetectorSample* s, const Box& box, double gain, double dt) {
  return forObjectReturns(s, box, dt,
                          [gain](Point* p) { p->intensity = static_cast<float>(std::clamp(p->intensity * gain, 0.0, 1.0)); });
}

std::size_t darkenObject(DetectorSample* s, const Box& box, double fraction, double dt, std::mt19937* rng) {
  std::bernoulli_distribution dark(std::clamp(fraction, 0.0, 1.0));
  std::size_t zeroed = 0;
  forObjectReturns(s, box, dt, [&](Point* p) {
    if (!dark(*rng)) return;
    if (p->intensity != 0.0f) ++zeroed;
    p->intensity = 0.0f;
  });
  return zeroed;
}

void dropPreviousSweep(DetectorSample* s) {
  s->previous.clear();
  s->has_previous = false;
  s->prev_to_current = Eigen::Isometry3d::Identity();
  s->velocity_valid.assign(s->boxes.size(), false);
}

void jitterSensorPose(DetectorSample* s, double dz, double pitch, double roll) {
  Eigen::Isometry3d J = Eigen::Isometry3d::Identity();
  J.translate(Eigen::Vector3d(0, 0, dz));
  J.rotate(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
  s->current = transformCloud(s->current, J);
  if (s->has_previous) {
    // Both sweeps come from the same (moved) mounting: the previous one in its own frame, and the ego motion seen
    // through the mounting.
    s->previous = transformCloud(s->previous, J);
    s->prev_to_current = J * s->prev_to_current * J.inverse();
  }
  // Small angles: the centre moves with the points, the box keeps its yaw about z.
  for (auto* boxes : {&s->boxes, &s->ignore})
    for (Box& b : *boxes) {
      const Eigen::Vector3d c = J * b.center();
      b.x = c.x(), b.y = c.y(), b.z = c.z();
    }
}

}  // namespace ret3d
