#include "ret3d/train/detector_dataset.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "ret3d/core/geometry.h"
#include "ret3d/core/log.h"
#include "ret3d/core/transform.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/track_velocity.h"

namespace ret3d {

namespace fs = std::filesystem;

namespace {

bool isModelClass(const ModelConfig& m, ObjectClass c) {
  return std::find(m.classes.begin(), m.classes.end(), c) != m.classes.end();
}

// Labels neither taught as objects nor as background. KITTI's evaluation ignores Van for Car, Person_sitting for
// Pedestrian and whatever overlaps DontCare; Truck and Tram (car-like) and Misc are real objects a detector may fire
// on, so they are not background either: ignore all of these, and never teach them as positives.
bool isIgnoredType(const ModelConfig& m, const std::string& type) {
  if (type == "DontCare" || type == "Misc") return true;
  if (type == "Van" || type == "Truck" || type == "Tram") return isModelClass(m, ObjectClass::Car);
  if (type == "Person_sitting") return isModelClass(m, ObjectClass::Pedestrian);
  return false;
}

bool hasImageBox(const kitti::Label& l) { return l.bbox[2] > l.bbox[0] && l.bbox[3] > l.bbox[1]; }
bool hasBox3d(const kitti::Label& l) { return l.h > 0 && l.w > 0 && l.l > 0; }

// A DontCare label without a 3D box (KITTI gives none) becomes the region behind its image box; true when `l` was
// such a label (and is no box).
bool addDontCareRegion(const kitti::Label& l, const kitti::Calibration& calib, std::vector<BevWedge>* regions) {
  if (l.type != "DontCare" || hasBox3d(l)) return false;
  if (hasImageBox(l)) regions->push_back(kitti::imageRegionWedge(calib, l.bbox[0], l.bbox[2], l.bbox[1], l.bbox[3]));
  return true;
}

}  // namespace

// Accumulates what decides a set's label cover and the image size its labels imply.
struct CoverEvidence {
  int objects = 0, without_image_box = 0;
  Eigen::Vector2d image_size = kitti::kImageSize;
  void add(const kitti::Label& l) {
    if (l.type == "DontCare") return;
    ++objects;
    if (!hasImageBox(l)) ++without_image_box;
    image_size = image_size.cwiseMax(Eigen::Vector2d(l.bbox[2] + 1, l.bbox[3] + 1));
  }
};

namespace {

// Where the labels exist when asked to detect it: camera 2's view when every object label has a 2D box there (KITTI),
// all around when some have none (the simulator labels objects outside the view with an empty 2D box).
LabelCover resolveCover(LabelCover asked, const CoverEvidence& e, const std::string& root) {
  if (asked != LabelCover::Auto) return asked;
  const LabelCover c = e.objects > 0 && e.without_image_box == 0 ? LabelCover::Camera : LabelCover::All;
  RET3D_INFO(root << ": labels cover " << labelCoverName(c) << " (auto: " << e.without_image_box << " of "
                  << e.objects << " object labels without a 2D box in image 2)");
  return c;
}

// The wedge a camera-cover set's labels exist in (nullopt for the other covers). Not grown by a margin: a truncated
// object whose centre lies just outside is still taught as a positive (the heads supervise positives everywhere), and
// just outside the image an unlabelled object may stand, which must not be taught as background.
std::optional<BevWedge> labelledView(LabelCover cover, const kitti::Calibration& calib, const CoverEvidence& e) {
  if (cover != LabelCover::Camera) return std::nullopt;
  return kitti::imageRegionWedge(calib, 0, e.image_size.x(), 0, e.image_size.y());
}

// Both layouts resolve ROOT/training first, as kitti::TrackingDataset / ObjectDataset do.
std::string detectLayout(const std::string& root) {
  const std::string dir = kitti::ObjectDataset(root).dir();
  std::error_code ec;
  if (fs::is_directory(fs::path(dir) / "label_02", ec)) return "tracking";
  if (fs::is_directory(fs::path(dir) / "label_2", ec)) return "object";
  if (fs::is_directory(fs::path(dir) / "velodyne", ec))
    for (const auto& e : fs::directory_iterator(fs::path(dir) / "velodyne", ec))
      if (e.is_directory(ec)) return "tracking";
  throw std::runtime_error(root + ": neither a KITTI tracking layout (training/label_02/SSSS.txt, "
                                  "velodyne/SSSS/FFFFFF.bin) nor an object layout (training/label_2/FFFFFF.txt, "
                                  "velodyne/FFFFFF.bin)");
}

}  // namespace

LabelCover labelCoverFromName(const std::string& name) {
  if (name == "auto") return LabelCover::Auto;
  if (name == "all") return LabelCover::All;
  if (name == "camera") return LabelCover::Camera;
  throw std::invalid_argument("labels cover '" + name + "': expected auto, all or camera");
}

std::string labelCoverName(LabelCover c) {
  return c == LabelCover::Auto ? "auto" : c == LabelCover::All ? "all" : "camera";
}

DetectorDataset::DetectorDataset(const std::vector<std::string>& roots, const ModelConfig& model, int max_frames)
    : DetectorDataset(
          [&] {
            std::vector<DetectorDataSource> s;
            for (const std::string& r : roots) s.push_back({r});
            return s;
          }(),
          model, max_frames) {}

DetectorDataset::DetectorDataset(const std::vector<DetectorDataSource>& sources, const ModelConfig& model,
                                 int max_frames)
    : model_(model), sources_(sources) {
  for (std::size_t k = 0; k < sources_.size(); ++k) {
    const DetectorDataSource& src = sources_[k];
    if (!(src.weight >= 0) || !std::isfinite(src.weight))
      throw std::invalid_argument(src.root + ": weight " + std::to_string(src.weight) + " is not a number >= 0");
    layouts_.push_back(detectLayout(src.root));
    CoverEvidence evidence;
    const std::size_t first = seqs_.size();
    if (layouts_.back() == "object") addObject(k, &evidence);
    else addTracking(k, &evidence);
    sources_[k].cover = resolveCover(src.cover, evidence, src.root);
    for (std::size_t i = first; i < seqs_.size(); ++i)
      seqs_[i].view = labelledView(sources_[k].cover, seqs_[i].calib, evidence);
  }
  if (frames_.empty()) {
    std::string all;
    for (const auto& s : sources_) all += (all.empty() ? "" : ", ") + s.root;
    throw std::runtime_error(all + ": no labelled frames with scans");
  }
  if (max_frames > 0 && static_cast<int>(frames_.size()) > max_frames) {
    // Spread the subset over the whole set rather than taking its beginning.
    std::vector<Frame> subset;
    for (int i = 0; i < max_frames; ++i) subset.push_back(frames_[i * frames_.size() / max_frames]);
    frames_ = subset;
  }
}

std::size_t DetectorDataset::setSize(std::size_t set) const {
  std::size_t n = 0;
  for (const Frame& f : frames_) n += seqs_[f.seq].set == set ? 1 : 0;
  return n;
}

void DetectorDataset::addTracking(std::size_t set, CoverEvidence* evidence) {
  const std::string& root = sources_[set].root;
  kitti::TrackingDataset ds(root);
  for (const std::string& name : ds.sequences()) {
    const std::vector<int> frames = ds.frames(name);
    if (frames.empty()) continue;
    if (!ds.hasLabels(name)) {
      RET3D_WARN(ds.labelPath(name) << ": no labels; sequence " << name << " skipped for training");
      continue;
    }
    Sequence s;
    s.set = set;
    s.root = root;
    s.name = name;
    s.poses = ds.lidarPoses(name);
    if (s.poses.empty()) RET3D_WARN("sequence " << name << ": no poses; the ego motion is taken as zero");
    const kitti::Calibration calib = ds.calibration(name);
    s.calib = calib;
    const int last = frames.back();
    s.boxes.resize(last + 1);
    s.types.resize(last + 1);
    s.dont_care.resize(last + 1);
    const std::vector<kitti::Label> labels = kitti::readTrackingLabels(ds.labelPath(name));
    for (const kitti::Label& l : labels) {
      if (l.frame < 0 || l.frame > last) continue;
      evidence->add(l);
      if (addDontCareRegion(l, calib, &s.dont_care[l.frame])) continue;
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

void DetectorDataset::addObject(std::size_t set, CoverEvidence* evidence) {
  const std::string& root = sources_[set].root;
  kitti::ObjectDataset ds(root);
  std::error_code ec;
  std::vector<std::string> unlabelled;
  for (const std::string& name : ds.frames()) {
    if (!fs::is_regular_file(ds.velodynePath(name), ec)) continue;  // labels without a scan
    if (!fs::is_regular_file(ds.labelPath(name), ec)) {
      unlabelled.push_back(name);
      continue;
    }
    const kitti::Calibration calib = ds.calibration(name);
    Sequence s;
    s.set = set;
    s.object = true;
    s.calib = calib;
    s.root = root;
    s.name = name;
    s.boxes.resize(1);
    s.types.resize(1);
    s.dont_care.resize(1);
    for (const kitti::Label& l : kitti::readObjectLabels(ds.labelPath(name))) {
      evidence->add(l);
      if (addDontCareRegion(l, calib, &s.dont_care[0])) continue;
      s.boxes[0].push_back(kitti::labelToBox(l, calib));
      s.types[0].push_back(l.type);
    }
    s.velocity_valid = {std::vector<bool>(s.boxes[0].size(), false)};  // one sweep: no velocity
    seqs_.push_back(std::move(s));
    frames_.push_back({seqs_.size() - 1, 0, -1});
  }
  if (!unlabelled.empty())
    RET3D_WARN(root << ": " << unlabelled.size() << " scan(s) without a label file (e.g. " << ds.labelPath(unlabelled[0])
                    << ") skipped for training");
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
  DetectorSample out;
  out.labelled_view = s.view;
  out.ignore_regions = s.dont_care[f.frame];
  if (s.object) {
    out.id = s.name;
    out.current = kitti::readVelodyne(kitti::ObjectDataset(s.root).velodynePath(s.name));
  } else {
    kitti::TrackingDataset ds(s.root);
    char id[64];
    std::snprintf(id, sizeof(id), "%s/%06d", s.name.c_str(), f.frame);
    out.id = id;
    out.current = kitti::readVelodyne(ds.velodynePath(s.name, f.frame));
    if (f.previous >= 0) {
      out.previous = kitti::readVelodyne(ds.velodynePath(s.name, f.previous));
      out.has_previous = true;
      out.prev_to_current = motion(s, f.previous, f.frame);
    }
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

std::vector<std::size_t> epochOrder(const DetectorDataset& data, unsigned seed, int epoch) {
  std::vector<std::size_t> order;
  order.reserve(data.size());
  // The fractional draws use their own generator, so with integer weights the shuffle below is the one of the plain
  // (unweighted) order.
  std::mt19937 draw_rng(seed * 6151u + static_cast<unsigned>(epoch) * 31u + 17u);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (std::size_t i = 0; i < data.size(); ++i) {
    const double w = data.sources()[data.setOf(i)].weight;
    const double whole = std::floor(w), frac = w - whole;
    int copies = static_cast<int>(whole);
    if (frac > 0 && U(draw_rng) < frac) ++copies;
    for (int c = 0; c < copies; ++c) order.push_back(i);
  }
  std::mt19937 order_rng(seed * 7919u + static_cast<unsigned>(epoch));
  std::shuffle(order.begin(), order.end(), order_rng);
  return order;
}

namespace {

// A rotation about z, then a flip about the x axis and a scaling: one similarity for points, boxes and wedges.
struct Similarity {
  double angle = 0, scale = 1, c = 1, sn = 0;
  bool flip = false;

  void moveCloud(PointCloud* cloud) const {
    for (Point& p : cloud->points) {
      const double y = flip ? -p.y : p.y;
      const double x = p.x;
      p.x = static_cast<float>(scale * (c * x - sn * y));
      p.y = static_cast<float>(scale * (sn * x + c * y));
      p.z = static_cast<float>(scale * p.z);
    }
  }
  void moveBox(Box* b) const {
    if (flip) b->y = -b->y, b->yaw = -b->yaw, b->vy = -b->vy;
    const double x = b->x, y = b->y, vx = b->vx, vy = b->vy;
    b->x = scale * (c * x - sn * y);
    b->y = scale * (sn * x + c * y);
    b->z *= scale;
    b->vx = scale * (c * vx - sn * vy);
    b->vy = scale * (sn * vx + c * vy);
    b->yaw = wrapAngle(b->yaw + angle);
    b->length *= scale, b->width *= scale, b->height *= scale;
  }
  Eigen::Vector2d moveVector(Eigen::Vector2d v) const {
    if (flip) v.y() = -v.y();
    return Eigen::Vector2d(scale * (c * v.x() - sn * v.y()), scale * (sn * v.x() + c * v.y()));
  }
  void moveWedge(BevWedge* w) const {
    w->apex = moveVector(w->apex);
    w->ray_a = moveVector(w->ray_a).normalized();
    w->ray_b = moveVector(w->ray_b).normalized();
    w->margin *= scale;
  }
  void apply(DetectorSample* s) const {
    moveCloud(&s->current);
    if (s->has_previous) moveCloud(&s->previous);
    for (Box& b : s->boxes) moveBox(&b);
    for (Box& b : s->ignore) moveBox(&b);
    for (BevWedge& w : s->ignore_regions) moveWedge(&w);
    if (s->labelled_view) moveWedge(&*s->labelled_view);
  }
};

// Global rotation (within rotation_range), flip (half of the time, when allowed) and scale (scale_min-scale_max),
// drawn in that order.
Similarity drawSimilarity(const TrainOptions& t, std::mt19937* rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Similarity m;
  m.angle = t.rotation_range > 0 ? (2 * U(*rng) - 1) * t.rotation_range : 0.0;
  m.flip = t.flip && U(*rng) < 0.5;
  m.scale = t.scale_min + (t.scale_max - t.scale_min) * U(*rng);
  m.c = std::cos(m.angle), m.sn = std::sin(m.angle);
  return m;
}

// Keeps the points of both sweeps and the boxes where inside_kept(x, y); a box left out becomes an ignored one (its
// points are gone: neither an object nor background).
template <class InsideKept>
void keepInside(DetectorSample* s, InsideKept inside_kept) {
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
      s->ignore.push_back(s->boxes[i]);
    }
  }
  s->boxes = std::move(boxes);
  s->velocity_valid = std::move(valid);
}

}  // namespace

void augmentSample(DetectorSample* s, const TrainOptions& t, const BevGeometry& grid, std::mt19937* rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  if (s->has_previous && !s->prev_to_current.isApprox(Eigen::Isometry3d::Identity())) {
    s->previous = transformCloud(s->previous, s->prev_to_current);
    s->prev_to_current = Eigen::Isometry3d::Identity();
  }
  drawSimilarity(t, rng).apply(s);
  // Random clipping: keep a random window covering 60-100 % of each side of the grid grown by 2 m on every side (a
  // 100 m square for the +-48 m grid). It once was that square whatever the grid, which cut every object beyond 50 m
  // out of 30 % of a +-80 m grid's samples.
  if (U(*rng) < t.crop_probability) {
    const double sx = grid.x_max - grid.x_min + 4, sy = grid.y_max - grid.y_min + 4;
    const double wx = sx * (0.6 + 0.4 * U(*rng)), wy = sy * (0.6 + 0.4 * U(*rng));
    const double x0 = grid.x_min - 2 + (sx - wx) * U(*rng), y0 = grid.y_min - 2 + (sy - wy) * U(*rng);
    keepInside(s, [=](double x, double y) { return x >= x0 && x < x0 + wx && y >= y0 && y < y0 + wy; });
  }
  // Block input: blank one to three random squares (2-8 m), as occlusions do, centred anywhere on the grid but its
  // outer 8 m.
  if (U(*rng) < t.block_probability) {
    const int n = 1 + static_cast<int>(U(*rng) * 3);
    const double bx = grid.x_max - grid.x_min - 16, by = grid.y_max - grid.y_min - 16;
    std::vector<std::array<double, 3>> blocks;
    for (int k = 0; k < n; ++k)
      blocks.push_back({grid.x_min + 8 + bx * U(*rng), grid.y_min + 8 + by * U(*rng), 1 + 3 * U(*rng)});
    keepInside(s, [=](double x, double y) {
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
