// Box refinement from the points: the BEV grid (0.25 m cells) blurs where an object is, but its raw returns fix it
// to a few centimetres. After NMS:
// - faces (rigid boxy classes: cars): the box is moved so that its sides facing the sensor touch the visible faces
//   (keeping the predicted length and width), and its top is set from the highest returns (keeping the bottom; far
//   away, where the beams are sparse, within the slack the beam spacing leaves).
//   Faces hidden from the sensor keep the network's estimate, except with hidden_midpoint: along an axis whose two
//   faces are both hidden (a car seen end-on), the visible face spans the car, and its returns centre the box; and
//   with grow, a size grows (the visible face staying) to hold returns seen beyond the far face.
//   With heading_search_deg, a car's heading is first fitted to the outline of its returns (an L-shape fit); with
//   heading_any, over every heading.
// - centroid (small classes: pedestrians, cyclists): the box centre is put at the centroid of its returns moved away
//   from the sensor by a per-class offset (the visible surface lies in front of the centre; measured on training
//   data), twice, so that the returns are re-selected around the moved box.
// - score_calibration: the score of a refined box re-estimated from the returns that hold it and how they fit it.
#pragma once

#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

struct PointRefineOptions {
  std::vector<ObjectClass> faces;    // the classes refined by their faces
  // The classes refined by their centroid, each with the offset of its box centre behind the centroid (m).
  std::vector<std::pair<ObjectClass, double>> centroid;
  // A face's position: this quantile of the returns' coordinate toward the sensor (robust to stray returns).
  double quantile = 0.9;
  double surface_gap = 0.05;       // box side beyond the outermost surface (m), as labellers draw boxes
  double margin = 0.3;             // returns within this distance outside the box count (m)
  double ground_clearance = 0.3;   // returns less than this above the box bottom are taken as ground (m)
  double max_shift = 0.6;          // largest move of the centre along each box axis (m)
  int min_points = 3;              // fewer returns: the box is left as it is
  bool height = true;              // faces: also set the top from the highest returns
  bool centroid_height = false;    // centroid: the same for the centroid classes
  // The sensor's vertical beam spacing (deg): a far object's top may lie up to range x spacing above its highest
  // return, so the top is the network's estimate clamped to [highest return, highest return + that slack]. 0 = the
  // highest return is the top (on the tuning set 0.15 and 0 scored alike, 0.4 lower).
  double vertical_resolution_deg = 0.0;
  double centroid_margin = 0.1;    // centroid: returns within this distance outside the box count (m)
  // faces: along an axis whose faces the sensor cannot see (a car seen end-on), the centre is the midpoint of the
  // returns of the visible face, which spans that axis.
  bool hidden_midpoint = false;
  // faces: a size grows (keeping the visible face) to hold the returns seen beyond the far face.
  bool grow = false;
  // faces: the heading fitted to the returns' outline before the faces are placed: headings within this angle of
  // the network's (deg, below 45 so that length stays length) are scored by the closeness criterion of Zhang et al.
  // (2017, "Efficient L-shape fitting for vehicle detection using laser scanners"): the returns should lie close to
  // one of the two faces of each axis. 0 = the network's heading is kept.
  double heading_search_deg = 0.0;
  // faces: the search covers every heading (a quarter turn, centred on the network's), and which of the outline's
  // two axes is the length is then chosen from the returns: the one along which the returns fit within the network's
  // length and width (a side seen longer than the box is wide is a side); when both fit (a rear face, a short L), the
  // axis nearer the network's heading. For real scans, where the network's heading of a car is often a quarter turn
  // or tens of degrees off while its returns' outline is sharp. Needs heading_search_deg > 0 for the step count.
  bool heading_any = false;
  double heading_step_deg = 1.0;
  int heading_min_points = 10;     // fewer returns: the network's heading is kept
  // Score calibration, per class: after the refinement a box's score becomes sigmoid(w . f) with the features
  // f = [1, logit(score), log(1 + n), r / 40, log(1 + n) r / 40, logit(score) log(1 + n), a, a^2, e]:
  // - n the returns in the box (its footprint grown by margin, from ground_clearance above its bottom to margin
  //   above its top);
  // - r its range (m); a = |sin(heading - bearing)|, 0 seen end-on, 1 seen side-on;
  // - e the median distance of those returns to the nearest face of the box (m, at most kMaxResidual; kMaxResidual
  //   with fewer than 3 returns).
  // The network scores a box from a blurred grid; how many returns hold the refined box, and how closely they lie
  // on its faces, say how well it fits them. The weights are fitted on labelled data by
  // scripts/fit_score_calibration.py. Empty = scores as they are.
  std::vector<std::pair<ObjectClass, std::vector<double>>> score_calibration;
  // Classes whose boxes need clear space right above their top (people: nothing stands on a head, where a pole, a
  // trunk or a sign post runs on above the height of a person): a box of these classes with more than
  // clear_above_max_returns returns inside its footprint from clear_above_gap to clear_above_height above its top is
  // removed. Empty = off.
  std::vector<ObjectClass> clear_above;
  double clear_above_gap = 0.2;      // m above the box's top
  double clear_above_height = 1.2;   // m above the box's top
  int clear_above_max_returns = 2;
  static constexpr std::size_t kCalibrationFeatures = 9;
  static constexpr double kMaxResidual = 0.5;

  bool enabled() const {
    return !faces.empty() || !centroid.empty() || !score_calibration.empty() || !clear_above.empty();
  }
  // Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
};

// Refines, in place, the boxes of the configured classes, and removes those of the clear_above classes that have
// returns right above them. The cloud and the boxes are in the sensor frame (the sensor at the origin, z up). Other
// boxes are untouched. Returns the number of boxes changed (refined or removed).
std::size_t refineBoxesFromPoints(const PointCloud& cloud, std::vector<Box>* boxes, const PointRefineOptions& options);

// Heading from motion: a box of a listed class moving at least at its class's speed (m/s) gets the heading of its
// predicted velocity (people walk the way they face; the network's heading of a pedestrian is often off by a
// quarter turn). Returns the number of boxes changed.
std::size_t headingFromVelocity(std::vector<Box>* boxes, const std::vector<std::pair<ObjectClass, double>>& min_speed);

}  // namespace ret3d
