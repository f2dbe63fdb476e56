// Boxes for the tests: a box of a given geometry, the typical car, and a check that two boxes have the same centre and
// size.
#pragma once

#include <gtest/gtest.h>

#include "ret3d/core/types.h"

namespace ret3d {
namespace test {

// A box of the given centre, size (length along the heading, width across, height) and heading; class Unknown.
inline Box makeBox(double x, double y, double z, double length, double width, double height, double yaw = 0.0) {
  return Box{x, y, z, length, width, height, yaw};
}

// A car-sized box (4 x 1.8 x 1.5 m) centred at (x, y, 0), heading along x, labelled Car.
inline Box carBox(double x, double y) {
  Box b = makeBox(x, y, 0.0, 4.0, 1.8, 1.5);
  b.label = ObjectClass::Car;
  return b;
}

// The same centre and size within tol (0: exactly); the heading and the rest are the caller's to compare.
inline void expectSameCentreAndSize(const Box& a, const Box& b, double tol) {
  const char* names[] = {"x", "y", "z", "length", "width", "height"};
  const double va[] = {a.x, a.y, a.z, a.length, a.width, a.height};
  const double vb[] = {b.x, b.y, b.z, b.length, b.width, b.height};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(va[k], vb[k], tol) << names[k];
}

}  // namespace test
}  // namespace ret3d
