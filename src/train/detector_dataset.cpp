#include "ret3d/train/detector_dataset.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/core/log.h"
#include "ret3d/core/transform.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/track_velocity.h"

namespace ret3d {

namespace {

bool isModelClass(const ModelConfig& m, ObjectClass c) {
  return std::find(m.classes.begin(), m.classes.end(), c) != m.classes.end();
}

// Types KITTI's benchmark neither counts nor penalises for one of our classes.
bool isIgnoredType(const ModelConfig& m, const std::string& type) {
  if (type == "DontCare") return true;
  if (type == "Van") return isModelClass(m, ObjectClass::Car);
  if (type == "Person_sitting") return isModelClass(m, ObjectClass::Pedestrian);
  return false;
}

}  // namespace

DetectorDataset::DetectorDataset(const std::vector<std::string>& roots, const ModelConfig& model, int max_frames)
    : model_(model) {
  for (const std::string& root : roots) addRoot(root);
  if (frames_.empty()) {
    std::string all;
    for (const std::string& r : roots) all += (all.empty() ? "" : ", ") + r;
    throw std::runtime_error(all + ": no labelled frames with scans (KITTI tracking layout expected)");
  }
  if (max_frames > 0 && static_cast<int>(frames_.size()) > max_frames) {
    // Spread the subset over the whole set rather than taking its beginning.
    std::vector<Frame> subset;
    for (int i = 0; i < max_frames; ++i) subset.push_back(frames_[i * frames_.size() / max_frames]);
    frames_ = subset;
  }
}

void DetectorDataset::addRoot(const std::string& root) {
  kitti::TrackingDataset ds(root);
  for (const std::string& name : ds.sequences()) {
    const std::vector<int> frames = ds.frames(name);
    if (frames.empty()) continue;
    if (!ds.hasLabels(name)) {
      RET3D_WARN(ds.labelPath(name) << ": no labels; sequence " << name << " skipped for training");
      continue;
    }
    Sequence s;
    s.root = root;
    s.name = name;
    s.poses = ds.lidarPoses(name);
    if (s.poses.empty()) RET3D_WARN("sequence " << name << ": no poses; the ego motion is taken as zero");
    const kitti::Calibration calib = kitti::readCalibration(ds.calibPath(name));
    const int last = frames.back();
    s.boxes.resize(last + 1);
    s.types.resize(last + 1);
    for (const kitti::Label& l : kitti::readTrackingLabels(ds.labelPath(name))) {
      if (l.frame < 0 || l.frame > last) continue;
      Box b = kitti::labelToBox(l, calib);
      s.boxes[l.frame].push_back(b);
      s.types[l.frame].push_back(l.type);
    }
    // Velocity targets from the same track in the previous (else the next) frame, both in the current frame.
    s.velocity_valid = setTrackVelocities(&s.boxes, s.poses, model_.sweep_interval);
    seqs_.push_back(std::move(s));
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const int prev = i > 0 && frames[i - 1] == frames[i] - 1 ? frames[i - 1] : -1;
      frames_.push_back({seqs_.size() - 1, frames[i], prev});
    }
  }
}

Eigen::Isometry3d DetectorDataset::motion(const Sequence& s, int from, int to) const {
  if (from < 0 || to < 0 || from >= static_cast<int>(s.poses.size()) || to >= static_cast<int>(s.poses.size()))
    return Eigen::Isometry3d::Identity();
  return s.poses[to].inverse() * s.poses[from];
}

std::vector<Box> DetectorDataset::allBoxes() const {
  std::vector<Box> out;
  for (const auto& s : seqs_)
    for (const auto& frame : s.boxes)
      for (const Box& b : frame)
        if (isModelClass(model_, b.label)) out.push_back(b);
  return out;
}

DetectorSample DetectorDataset::load(std::size_t i) const {
  const Frame& f = frames_.at(i);
  const Sequence& s = seqs_[f.seq];
  kitti::TrackingDataset ds(s.root);
  DetectorSample out;
  char id[64];
  std::snprintf(id, sizeof(id), "%s/%06d", s.name.c_str(), f.frame);
  out.id = id;
  out.current = kitti::readVelodyne(ds.velodynePath(s.name, f.frame));
  if (f.previous >= 0) {
    out.previous = kitti::readVelodyne(ds.velodynePath(s.name, f.previous));
    out.has_previous = true;
    out.prev_to_current = motion(s, f.previous, f.frame);
  }
  const auto& boxes = s.boxes[f.frame];
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    const Box& b = boxes[k];
    if (isIgnoredType(model_, s.types[f.frame][k])) {
      out.ignore.push_back(b);
      continue;
    }
    if (!isModelClass(model_, b.label)) continue;
    out.boxes.push_back(b);
    out.velocity_valid.push_back(s.velocity_valid[f.frame][k]);
  }
  return out;
}

void augmentSample(DetectorSample* s, const TrainOptions& t, std::mt19937* rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  if (s->has_previous && !s->prev_to_current.isApprox(Eigen::Isometry3d::Identity())) {
    s->previous = transformCloud(s->previous, s->prev_to_current);
    s->prev_to_current = Eigen::Isometry3d::Identity();
  }
  // Global rotation, flip about the x axis and scaling: one similarity applied to points and boxes.
  const double angle = t.rotation_range > 0 ? (2 * U(*rng) - 1) * t.rotation_range : 0.0;
  const bool flip = t.flip && U(*rng) < 0.5;
  const double scale = t.scale_min + (t.scale_max - t.scale_min) * U(*rng);
  const double c = std::cos(angle), sn = std::sin(angle);
  auto moveCloud = [&](PointCloud* cloud) {
    for (Point& p : cloud->points) {
      const double y = flip ? -p.y : p.y;
      const double x = p.x;
      p.x = static_cast<float>(scale * (c * x - sn * y));
      p.y = static_cast<float>(scale * (sn * x + c * y));
      p.z = static_cast<float>(scale * p.z);
    }
  };
  auto moveBox = [&](Box* b) {
    if (flip) b->y = -b->y, b->yaw = -b->yaw, b->vy = -b->vy;
    const double x = b->x, y = b->y, vx = b->vx, vy = b->vy;
    b->x = scale * (c * x - sn * y);
    b->y = scale * (sn * x + c * y);
    b->z *= scale;
    b->vx = scale * (c * vx - sn * vy);
    b->vy = scale * (sn * vx + c * vy);
    b->yaw = wrapAngle(b->yaw + angle);
    b->length *= scale, b->width *= scale, b->height *= scale;
  };
  moveCloud(&s->current);
  if (s->has_previous) moveCloud(&s->previous);
  for (Box& b : s->boxes) moveBox(&b);
  for (Box& b : s->ignore) moveBox(&b);

  auto filter = [&](auto inside_kept) {
    for (PointCloud* cloud : {&s->current, &s->previous}) {
      PointCloud kept;
      for (const Point& p : cloud->points)
        if (inside_kept(p.x, p.y)) kept.push_back(p);
      *cloud = std::move(kept);
    }
    std::vector<Box> boxes;
    std::vector<bool> valid;
    for (std::size_t i = 0; i < s->boxes.size(); ++i) {
      if (inside_kept(s->boxes[i].x, s->boxes[i].y)) {
        boxes.push_back(s->boxes[i]);
        valid.push_back(s->velocity_valid[i]);
      } else {
        s->ignore.push_back(s->boxes[i]);  // its points are gone: neither an object nor background
      }
    }
    s->boxes = std::move(boxes);
    s->velocity_valid = std::move(valid);
  };
  // Random clipping: keep a random window covering 60-100 % of each side of a 100 m square.
  if (U(*rng) < t.crop_probability) {
    const double wx = 100 * (0.6 + 0.4 * U(*rng)), wy = 100 * (0.6 + 0.4 * U(*rng));
    const double x0 = -50 + (100 - wx) * U(*rng), y0 = -50 + (100 - wy) * U(*rng);
    filter([=](double x, double y) { return x >= x0 && x < x0 + wx && y >= y0 && y < y0 + wy; });
  }
  // Block input: blank one to three random squares (2-8 m), as occlusions do.
  if (U(*rng) < t.block_probability) {
    const int n = 1 + static_cast<int>(U(*rng) * 3);
    std::vector<std::array<double, 3>> blocks;
    for (int k = 0; k < n; ++k) blocks.push_back({-40 + 80 * U(*rng), -40 + 80 * U(*rng), 1 + 3 * U(*rng)});
    filter([=](double x, double y) {
      for (const auto& b : blocks)
        if (std::abs(x - b[0]) < b[2] && std::abs(y - b[1]) < b[2]) return false;
      return true;
    });
  }
}

BevGeometry multiscaleGeometry(const BevGeometry& g, const TrainOptions& t, std::mt19937* rng) {
  if (t.multiscale_n_max < t.multiscale_n_min) return g;
  const int n = std::uniform_int_distribution<int>(t.multiscale_n_min, t.multiscale_n_max)(*rng);
  const int side = 32 * (t.multiscale_base + n);  // LWD-3D eq. (4)
  if (side <= 0) return g;
  BevGeometry out = g;
  double cx = 0.5 * (g.x_min + g.x_max), cy = 0.5 * (g.y_min + g.y_max);
  const double half = 0.5 * side * g.resolution;
  if (t.multiscale_random_position) {
    // Whole cells only, so the crop's cells coincide with the full grid's.
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const int free_x = std::max(0, static_cast<int>(std::lround((g.x_max - g.x_min) / g.resolution)) - side);
    const int free_y = std::max(0, static_cast<int>(std::lround((g.y_max - g.y_min) / g.resolution)) - side);
    cx = g.x_min + half + g.resolution * std::floor(U(*rng) * (free_x + 1));
    cy = g.y_min + half + g.resolution * std::floor(U(*rng) * (free_y + 1));
  }
  out.x_min = cx - half, out.x_max = cx + half;
  out.y_min = cy - half, out.y_max = cy + half;
  return out;
}

}  // namespace ret3d
