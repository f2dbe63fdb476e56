// Anchor priors of the anchor head (LWD-3D §2.4): per class, k-means over the training boxes' sizes, with z and
// height (the paper's 3D prior (x, y, z, w, h, c)).
#pragma once

#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

struct Anchor {
  ObjectClass label = ObjectClass::Unknown;
  double length = 0, width = 0, height = 0;  // metres
  double z = 0;                              // centre height in the sensor frame
  int stride = 0;                            // the head scale that predicts with this anchor (0 = not assigned)
};

// IoU of two axis-aligned 3D boxes sharing their BEV centre: min(l) min(w) overlap(z) / union. The k-means distance
// is 1 - this (YOLO's IoU distance, extended by z and height).
double anchorShapeIoU(const Anchor& a, double length, double width, double height, double z);

// k anchors per class by k-means (k-means++ seeding from `seed`, IoU distance, mean update) over the boxes of that
// class. A class with fewer than k distinct boxes gets as many anchors as it has; a class with none gets the KITTI
// mean size (with a warning). Anchors of one class are sorted by BEV area.
std::vector<Anchor> kmeansAnchors(const std::vector<Box>& boxes, const std::vector<ObjectClass>& classes, int k,
                                  unsigned seed = 1);

// Typical KITTI sizes, k per class (slightly spread), for an untrained model.
std::vector<Anchor> defaultAnchors(const std::vector<ObjectClass>& classes, int k);

// YOLO-style split over the scales: an anchor predicts at the coarsest stride whose cell (stride * resolution) is at
// most `fraction` of its longer side, else at the finest stride.
void assignAnchorStrides(std::vector<Anchor>* anchors, std::vector<int> strides, double resolution, double fraction);

}  // namespace ret3d
