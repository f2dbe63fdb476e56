// `ret3d draw`: a bird's-eye-view PNG of one scan with boxes over it: the points in grey, KITTI ground truth in white
// (when --labels and --calib are given), and detections coloured by class as in rviz (classColour of
// src/ros/markers.h: Car green, Pedestrian magenta, Cyclist orange), each with a line from its centre to its front.
// The detections come from the LWD-3D detector run in-process (--models DIR or --detector-model FILE; no calibration
// needed, boxes stay in the LiDAR frame), or from a KITTI result file (--pred FILE, camera coordinates, needs --calib).
//   ret3d draw --scan ../shared/data/unlabeled_scans/000010.bin --models models/lwd3d --out docs/scan.png
//   ret3d draw --scan velodyne/000134.bin --labels label_2/000134.txt --calib calib/000134.txt
//              --models models/lwd3d --view front --out real_000134.png
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "ret3d/core/detections.h"
#include "ret3d/core/geometry.h"
#include "ret3d/core/log.h"
#include "ret3d/io/kitti.h"
#include "ret3d/ros/markers.h"
#include "tools/bev_image.h"
#include "tools/command.h"
#include "tools/pipeline_options.h"

namespace ret3d {
namespace tools {
namespace {

namespace fs = std::filesystem;

struct DrawArgs {
  pipeline::PipelineConfig pipeline;
  std::string scan, labels, calib, pred, out, title;
  std::string view = "around", extent, shade = "height";
  int size = 1000;
  bool no_scores = false;
};

const Rgb kWhite{255, 255, 255};
const Rgb kOtherGt{150, 150, 150};   // labelled objects the benchmark ignores (Van, Truck, Person_sitting, ...)
const Rgb kRings{45, 45, 75};
const Rgb kFov{110, 110, 40};
const Rgb kEgo{80, 160, 255};
const Rgb kText{230, 230, 230};

std::vector<double> parseExtent(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::invalid_argument("--extent: '" + item + "' is not a number (expected x_min,x_max,y_min,y_max)");
    }
  }
  if (v.size() != 4)
    throw std::invalid_argument("--extent: expected 4 numbers x_min,x_max,y_min,y_max, got '" + s + "'");
  return v;
}

std::string fixed(double v, int decimals) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(decimals) << v;
  return o.str();
}

// The bearings (radians, in the LiDAR frame) between which ground points project into camera 2's image (KITTI's
// 1242 pixels wide): the part of the scan the labels cover.
bool cameraFov(const kitti::Calibration& calib, double* left, double* right) {
  bool any = false;
  for (int i = -900; i <= 900; ++i) {
    const double a = i * M_PI / 1800.0;
    const Eigen::Vector3d p(30.0 * std::cos(a), 30.0 * std::sin(a), -1.0);
    const auto uv = calib.projectRect(calib.veloToRect(p));
    if (!uv || uv->x() < 0 || uv->x() > 1242) continue;
    if (!any) *right = *left = a;
    *right = std::min(*right, a);
    *left = std::max(*left, a);
    any = true;
  }
  return any;
}

// Boxes of a KITTI label/result file in the LiDAR frame; `other` receives the non-DontCare labels of other types.
std::vector<Box> readBoxes(const std::string& path, const kitti::Calibration& calib, std::vector<Box>* other) {
  std::vector<Box> boxes;
  for (const kitti::Label& l : kitti::readObjectLabels(path)) {
    if (classFromName(l.type)) boxes.push_back(kitti::labelToBox(l, calib));
    else if (other && l.type != "DontCare") other->push_back(kitti::labelToBox(l, calib));
  }
  return boxes;
}

// One line of the legend: pieces of text, each in its colour.
using TextLine = std::vector<std::pair<std::string, Rgb>>;

// Draws a line's pieces one after the other from (col, row); returns the end column.
int drawLine(BevImage& img, int col, int row, const TextLine& line, int scale) {
  for (const auto& [text, colour] : line) col += img.drawText(col, row, text, colour, scale) + 6 * scale;
  return col;
}

void checkDrawArgs(const DrawArgs& a, bool detector) {
  if (a.scan.empty() || a.out.empty()) throw std::invalid_argument("--scan and --out are required");
  if (detector && !a.pred.empty())
    throw std::invalid_argument("--pred and a detector (--models/--detector-model) exclude each other: draw one set");
  if ((!a.labels.empty() || !a.pred.empty()) && a.calib.empty())
    throw std::invalid_argument("--labels and --pred are KITTI camera coordinates: they need --calib FILE");
  if (a.shade != "height" && a.shade != "intensity")
    throw std::invalid_argument("--shade: 'height' or 'intensity', not '" + a.shade + "'");
  if (a.view != "around" && a.view != "front")
    throw std::invalid_argument("--view: 'around' or 'front', not '" + a.view + "'");
  if (a.size < 100 || a.size > 8000) throw std::invalid_argument("--size: 100 to 8000 pixels");
}

// The boxes to draw and where they come from (for the legend).
struct DrawnDetections {
  std::vector<Box> boxes;
  std::string source;  // empty: none drawn
};

// The detector in-process (the same code path as `ret3d detect --stages base`, one sweep); `view` becomes its grid.
DrawnDetections runDetector(DrawArgs& a, const PointCloud& cloud, BevView* view) {
  DrawnDetections d;
  a.pipeline.stages = {"base"};
  pipeline::OfflinePipeline p(withPackageDir(a.pipeline));
  d.boxes = p.run(&cloud, nullptr, Eigen::Isometry3d::Identity(), {}, 0.0, Eigen::Isometry3d::Identity()).boxes;
  const BevGeometry g = p.detector()->options().inferenceGeometry();
  view->x_min = g.x_min;
  view->x_max = g.x_max;
  view->y_min = g.y_min;
  view->y_max = g.y_max;
  const std::string model = a.pipeline.detector_model.empty() ? a.pipeline.models + "/detector.pt"
                                                              : a.pipeline.detector_model;
  const fs::path m(model);  // its folder and name say which model it is (models/lwd3d/detector.pt -> lwd3d/...)
  d.source = "LWD-3D " + (m.parent_path().filename() / m.filename()).string() + ", score >= " +
             p.detector()->options().inference.describeScoreThresholds();
  return d;
}

// A result file's boxes at or above --score-threshold.
DrawnDetections readPredictions(const DrawArgs& a, const kitti::Calibration& calib) {
  DrawnDetections d;
  d.boxes = readBoxes(a.pred, calib, nullptr);
  if (a.pipeline.score_threshold >= 0)
    d.boxes.erase(std::remove_if(d.boxes.begin(), d.boxes.end(),
                                 [&](const Box& b) { return b.score < a.pipeline.score_threshold; }),
                  d.boxes.end());
  d.source = fs::path(a.pred).filename().string();
  if (a.pipeline.score_threshold >= 0) d.source += ", score >= " + fixed(a.pipeline.score_threshold, 2);
  return d;
}

// --view front (KITTI's evaluated area in front of the car: camera 2 looks forward, 0-70 m ahead, 40 m to each side)
// or --extent over the default view, and the scale for --size pixels.
void applyViewArgs(const DrawArgs& a, BevView* view) {
  if (a.view == "front") {
    view->x_min = 0.0;
    view->x_max = 70.0;
    view->y_min = -40.0;
    view->y_max = 40.0;
  }
  if (!a.extent.empty()) {
    const auto e = parseExtent(a.extent);
    view->x_min = e[0];
    view->x_max = e[1];
    view->y_min = e[2];
    view->y_max = e[3];
  }
  view->pixels_per_metre = a.size / std::max(view->x_max - view->x_min, view->y_max - view->y_min);
}

// Background: range rings every 10 m, the camera's field of view, then the points.
void drawBackground(BevImage& img, const PointCloud& cloud, const std::optional<kitti::Calibration>& calib,
                    const std::string& shade) {
  for (int r = 10; r <= 150; r += 10) img.drawGroundCircle(0, 0, r, kRings);
  if (calib) {
    double left = 0, right = 0;
    if (cameraFov(*calib, &left, &right)) {
      for (const double ang : {left, right})
        img.drawGroundLine({0, 0}, {150 * std::cos(ang), 150 * std::sin(ang)}, kFov);
    }
  }
  img.drawPoints(cloud, shade == "height" ? PointShade::Height : PointShade::Intensity);
}

// Ego vehicle (a car-sized box at the sensor, facing forward), ground truth, then detections on top, each with its
// score just right of its outline unless no_scores. Returns the detections per class.
std::map<ObjectClass, int> drawBoxes(BevImage& img, double pixels_per_metre, const std::vector<Box>& gt,
                                     const std::vector<Box>& gt_other, const std::vector<Box>& dets, bool no_scores) {
  Box ego;
  ego.length = 4.0;
  ego.width = 1.8;
  img.drawBox(ego, kEgo, 1, true);
  const int thick = std::max(1, static_cast<int>(std::lround(pixels_per_metre / 8.0)));
  for (const Box& b : gt_other) img.drawBox(b, kOtherGt, thick, false);
  for (const Box& b : gt) img.drawBox(b, kWhite, thick + 2, false);
  std::map<ObjectClass, int> counts;
  for (const Box& b : dets) {
    const Rgb c = toRgb(classColour(b.label));
    img.drawBox(b, c, thick, true);
    ++counts[b.label];
    if (no_scores) continue;
    double col = -1e9, row = 1e9;
    for (const auto& corner : bevCorners(b)) {
      const Eigen::Vector2d px = img.toPixel(corner.x(), corner.y());
      col = std::max(col, px.x());
      row = std::min(row, px.y());
    }
    img.drawText(static_cast<int>(col) + 3, static_cast<int>(row), fixed(b.score, 2), c, 1);
  }
  return counts;
}

// The legend's lines: title, points and scale, detections per class, ground truth.
std::vector<TextLine> legendLines(const DrawArgs& a, std::size_t num_points, const DrawnDetections& d,
                                  std::map<ObjectClass, int>& counts, std::size_t num_gt, std::size_t num_gt_other,
                                  bool has_calib) {
  std::vector<TextLine> lines;
  lines.push_back({{a.title.empty() ? fs::path(a.scan).filename().string() : a.title, kText}});
  lines.push_back(
      {{std::to_string(num_points) + " points, grey by " + a.shade + "; rings every 10 m; scale bar 10 m", kText}});
  if (!d.source.empty()) {
    lines.push_back({{std::to_string(d.boxes.size()) + " detections (" + d.source + "):", kText}});
    TextLine per_class;
    for (const ObjectClass c : kDetectedClasses)
      per_class.push_back({std::string(className(c)) + " " + std::to_string(counts[c]) + " ", toRgb(classColour(c))});
    per_class.push_back({"(line from centre: heading)", kOtherGt});
    lines.push_back(per_class);
  }
  if (!a.labels.empty()) {
    TextLine truth{{"ground truth " + std::to_string(num_gt) + " ", kWhite}};
    if (num_gt_other > 0) truth.push_back({"other labels, ignored " + std::to_string(num_gt_other) + " ", kOtherGt});
    if (has_calib) truth.push_back({"camera view (labelled area)", kFov});
    lines.push_back(truth);
  }
  return lines;
}

// The map under a band holding the legend, so the legend hides nothing; the scale bar after the second line.
BevImage withLegend(const BevImage& img, const std::vector<TextLine>& lines, double pixels_per_metre) {
  const int scale = img.width() >= 800 ? 2 : 1;
  const int line_h = BevImage::textHeight(scale) + 4 * scale;
  BevImage page(img.width(), static_cast<int>(lines.size()) * line_h + 4 * scale + img.height());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const int row = 3 * scale + static_cast<int>(i) * line_h;
    const int end = drawLine(page, 3 * scale, row, lines[i], scale);
    if (i == 1) {  // the scale bar after "10 m:"
      const int bar_px = static_cast<int>(std::lround(10.0 * pixels_per_metre));
      page.fillRect(end, row + BevImage::textHeight(scale) / 2 - scale, bar_px, 2 * scale, kText);
    }
  }
  page.paste(img, 0, page.height() - img.height());
  return page;
}

int runDraw(DrawArgs a) {
  const bool detector = !a.pipeline.models.empty() || !a.pipeline.detector_model.empty();
  checkDrawArgs(a, detector);
  const PointCloud cloud = kitti::readVelodyne(a.scan);
  std::optional<kitti::Calibration> calib;
  if (!a.calib.empty()) calib = kitti::readCalibration(a.calib);

  BevView view;
  DrawnDetections dets;
  if (detector)
    dets = runDetector(a, cloud, &view);
  else if (!a.pred.empty())
    dets = readPredictions(a, *calib);
  std::vector<Box> gt, gt_other;
  if (!a.labels.empty()) gt = readBoxes(a.labels, *calib, &gt_other);
  applyViewArgs(a, &view);

  BevImage img(view);
  drawBackground(img, cloud, calib, a.shade);
  std::map<ObjectClass, int> counts = drawBoxes(img, view.pixels_per_metre, gt, gt_other, dets.boxes, a.no_scores);
  const BevImage page = withLegend(
      img, legendLines(a, cloud.size(), dets, counts, gt.size(), gt_other.size(), calib.has_value()),
      view.pixels_per_metre);

  if (fs::path(a.out).has_parent_path()) fs::create_directories(fs::path(a.out).parent_path());
  page.writePng(a.out);
  std::cout << "draw: " << a.out << " (" << page.width() << " x " << page.height() << "), " << cloud.size()
            << " points, " << dets.boxes.size() << " detections";
  if (!a.labels.empty()) std::cout << ", " << gt.size() << " ground-truth boxes";
  std::cout << std::endl;
  return 0;
}

CommandRegistrar reg("draw", "a bird's-eye-view PNG of a scan with ground truth and detections",
                     [](CLI::App& app) -> CommandRun {
  auto a = std::make_shared<DrawArgs>();
  pipeline::PipelineConfig& p = a->pipeline;
  app.add_option("--scan", a->scan, "velodyne scan (KITTI .bin, N x 4 float32)")->required()->check(CLI::ExistingFile);
  app.add_option("--out", a->out, "PNG file to write")->required();
  app.add_option("--labels", a->labels, "KITTI object label file (ground truth, drawn white; needs --calib)")
      ->check(CLI::ExistingFile);
  app.add_option("--calib", a->calib, "KITTI calibration file (for --labels and --pred)")->check(CLI::ExistingFile);
  app.add_option("--pred", a->pred, "KITTI object result file to draw (camera coordinates; needs --calib)")
      ->check(CLI::ExistingFile);
  app.add_option("--models", p.models, "run the detector of this folder (detector.pt) on the scan");
  app.add_option("--detector-model", p.detector_model, "run this detector model file (overrides --models)");
  app.add_option("--detector-config", p.detector_config, "detector YAML for inference options");
  app.add_option("--score-threshold", p.score_threshold, "minimum score (detector or --pred; default: the model's)");
  addGridExtentOption(app, &p.grid_extent);
  app.add_option("--threads", p.threads, "CPU threads for libtorch")->capture_default_str();
  app.add_option("--view", a->view, "around: the detector's grid (else 96 m x 96 m) around the sensor; front: 0-70 m "
                 "ahead, +-40 m")->capture_default_str();
  app.add_option("--extent", a->extent, "x_min,x_max,y_min,y_max in metres (overrides --view)");
  app.add_option("--size", a->size, "pixels along the longer side")->capture_default_str();
  app.add_option("--shade", a->shade, "point grey level from 'height' or 'intensity'")->capture_default_str();
  app.add_option("--title", a->title, "first line of the legend (default: the scan's file name)");
  app.add_flag("--no-scores", a->no_scores, "do not print each detection's score");
  return [a]() { return runDraw(*a); };
});

}  // namespace
}  // namespace tools
}  // namespace ret3d
