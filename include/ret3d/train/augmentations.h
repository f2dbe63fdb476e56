// Sim-to-real training augmentations (SensorAugmentOptions in detector_options.h): what separates simulated HDL-64E
// scans from real KITTI ones - lost rays, fewer beams, other intensities, no previous sweep, another mounting - plus
// ground-truth sampling (SECOND) from a database of objects cut from training folders.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "ret3d/core/types.h"
#include "ret3d/detector/detector_options.h"
#include "ret3d/sim/sensor_model.h"
#include "ret3d/train/detector_dataset.h"

namespace ret3d {

// One object of the ground-truth database: its box and the returns inside it, in its source frame's sensor frame.
struct GtObject {
  Box box;
  std::vector<Point> points;
};

struct GtDatabaseOptions {
  int min_points = 5;          // objects with fewer returns are left out
  double grow = 0.1;           // the box grows by this (m) at each side in length and width to catch edge returns
  double ground_margin = 0.05; // only returns this far above the box bottom (no ground comes along)
};

// Objects of the model's classes from every labelled frame (current sweep) of the given training folders.
std::vector<GtObject> buildGtDatabase(const DetectorDataset& data, const GtDatabaseOptions& o);
// Binary file: "RET3DGTDB1", the object count, then per object 8 doubles of box (x y z l w h yaw), the class, the
// point count and the points as x y z intensity floats. Readers throw naming the file when it is not one.
void writeGtDatabase(const std::string& path, const std::vector<GtObject>& objects);
std::vector<GtObject> readGtDatabase(const std::string& path);

// The region an object of a box is cut from (and pasted into): the box grown by `grow` in length and width, from
// `ground_margin` above its bottom to `grow` above its top.
class GtRegion {
 public:
  GtRegion(const Box& b, const GtDatabaseOptions& o);
  bool contains(const Point& p) const;

 private:
  double x_, y_, cos_, sin_, half_length_, half_width_, z_min_, z_max_;
};

class SensorAugmenter {
 public:
  // Loads the beam table (o.beam_sensor) when beam subsampling is on and the database (o.gt_database) when
  // ground-truth sampling is on; throws naming the file when either cannot be read.
  explicit SensorAugmenter(const SensorAugmentOptions& o);
  // With the beam elevations (degrees, ascending) and the database given directly (tests).
  SensorAugmenter(const SensorAugmentOptions& o, std::vector<double> beam_elevation_deg, std::vector<GtObject> db);

  // Applies the configured augmentations to a sample as loaded (before augmentSample): the previous sweep stays in
  // its own frame. Draws nothing from `rng` when every part is off.
  void apply(DetectorSample* s, std::mt19937* rng) const;

  // The parts, each applied unconditionally (apply() draws whether they run). Exposed for the tests.
  void pasteObjects(DetectorSample* s, std::mt19937* rng) const;
  void subsampleBeams(DetectorSample* s, int keep_every, int offset) const;

  std::size_t databaseSize() const { return db_.size(); }

 private:
  void indexDatabase();
  SensorAugmentOptions o_;
  sim::SensorModel beams_;  // only its elevation table is used
  std::vector<GtObject> db_;
  std::vector<std::vector<std::size_t>> by_class_;  // indices into db_ per ObjectClass value
};

// Drops each point with probability p + far * min(1, range / 80 m).
void dropRays(PointCloud* cloud, double p, double far, std::mt19937* rng);
// Sets exactly round(fraction * size) intensities to 0, drawn with weight proportional to range (far returns are
// the weak ones).
void zeroIntensities(PointCloud* cloud, double fraction, std::mt19937* rng);
// Multiplies the intensity of the returns inside `box` (the ground-truth cut region: the box grown a little) by
// `gain`, clamped to [0, 1]; in the previous sweep where the object was then (the box moved back by its velocity over
// `dt` seconds, into the previous sweep's frame). Returns the current sweep's points changed.
std::size_t scaleObjectIntensity(DetectorSample* s, const Box& box, double gain, double dt);
// Sets each return of `box` (both sweeps, as scaleObjectIntensity finds them) to intensity 0 with probability
// `fraction` (a dark object: SensorAugmentOptions::object_zero_probability). Returns how many returns of either sweep
// it turned from non-zero to 0.
std::size_t darkenObject(DetectorSample* s, const Box& box, double fraction, double dt, std::mt19937* rng);
// Removes the previous sweep; the velocities can no longer be seen, so they become invalid.
void dropPreviousSweep(DetectorSample* s);
// Moves the sensor: up by dz, then pitch and roll (rad) about its origin; points and boxes alike, yaw kept.
void jitterSensorPose(DetectorSample* s, double dz, double pitch, double roll);

}  // namespace ret3d
