// Box refinement from the points: the BEV grid (0.25 m cells) blurs where an object's faces are, but the raw returns
// on the faces the sensor sees fix them to a few centimetres. After NMS each box of a rigid class (cars) is moved so
// that its sides facing the sensor touch the visible faces (keeping the predicted length and width), and its top is
// set from the highest returns (keeping the bottom). Faces hidden from the sensor keep the network's estimate.
#pragma once

#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

struct PointRefineOptions {
  std::vector<ObjectClass> classes;  // the classes refined; empty = off
  // A face's position: this quantile of the returns' coordinate toward the sensor (robust to stray returns).
  double quantile = 0.9;
  double surface_gap = 0.05;       // box side beyond the outermost surface (m), as labellers draw boxes
  double margin = 0.3;             // returns within this distance outside the box count (m)
  double ground_clearance = 0.3;   // returns less than this above the box bottom are taken as ground (m)
  double max_shift = 0.6;          // largest move of the centre along each box axis (m)
  int min_points = 3;              // fewer returns: the box is left as it is
  bool height = true;              // also set the top from the highest returns

  bool enabled() const { return !classes.empty(); }
  // Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
};

// Refines, in place, the boxes of the configured classes. The cloud and the boxes are in the sensor frame (the
// sensor at the origin, z up). Other boxes are untouched. Returns the number of boxes changed.
std::size_t refineBoxesFromPoints(const PointCloud& cloud, std::vector<Box>* boxes, const PointRefineOptions& options);

}  // namespace ret3d
