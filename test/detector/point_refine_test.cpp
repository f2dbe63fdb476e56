#include "ret3d/detector/point_refine.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "ret3d/detector/detector_options.h"

namespace ret3d {
namespace {

Box carBox(double x, double y, double yaw, double l = 4.4, double w = 1.8, double h = 1.5) {
  Box b;
  b.x = x, b.y = y, b.z = -1.73 + 0.5 * h, b.yaw = yaw, b.length = l, b.width = w, b.height = h;
  b.label = ObjectClass::Car;
  b.score = 0.9f;
  return b;
}

// Returns on the faces of `b` (as a box shrunk by `gap` on every side) that the sensor at the origin sees: a face is
// visible when the sensor lies beyond its plane. Returns 5 cm apart, in rows
// about 10 cm apart from 0.4 m above the bottom to the top.
PointCloud visibleFaces(const Box& b, double gap = 0.05) {
  PointCloud cloud;
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double hl = 0.5 * b.length - gap, hw = 0.5 * b.width - gap, top = b.top() - gap;
  const double u_sensor = -(b.x * c + b.y * s), v_sensor = b.x * s - b.y * c;
  auto add = [&](double u, double v, double z) {
    Point p;
    p.x = static_cast<float>(b.x + u * c - v * s), p.y = static_cast<float>(b.y + u * s + v * c);
    p.z = static_cast<float>(z), p.intensity = 0.3f;
    cloud.push_back(p);
  };
  const int rows = static_cast<int>(std::ceil((top - b.bottom() - 0.4) / 0.1));
  for (int k = 0; k <= rows; ++k) {
    const double z = b.bottom() + 0.4 + (top - b.bottom() - 0.4) * k / rows;
    if (std::abs(u_sensor) > hl)
      for (double v = -hw; v <= hw + 1e-9; v += 0.05) add(u_sensor > 0 ? hl : -hl, v, z);
    if (std::abs(v_sensor) > hw)
      for (double u = -hl; u <= hl + 1e-9; u += 0.05) add(u, v_sensor > 0 ? hw : -hw, z);
  }
  return cloud;
}

// The box moved by (du, dv) along its own axes.
Box moved(Box b, double du, double dv) {
  b.x += du * std::cos(b.yaw) - dv * std::sin(b.yaw);
  b.y += du * std::sin(b.yaw) + dv * std::cos(b.yaw);
  return b;
}

PointRefineOptions carsOnly() {
  PointRefineOptions o;
  o.faces = {ObjectClass::Car};
  o.quantile = 1.0;  // clean synthetic faces: the outermost return is the face
  return o;
}

TEST(PointRefine, MovesTheBoxOntoTheVisibleFaces) {
  // Seen obliquely (from behind and the right): the rear and the right side fix both axes.
  const Box truth = carBox(12, 6, 0.3);
  const PointCloud cloud = visibleFaces(truth);
  std::vector<Box> boxes = {moved(truth, 0.35, -0.25)};
  EXPECT_EQ(refineBoxesFromPoints(cloud, &boxes, carsOnly()), 1u);
  EXPECT_NEAR(boxes[0].x, truth.x, 0.01);
  EXPECT_NEAR(boxes[0].y, truth.y, 0.01);
  EXPECT_DOUBLE_EQ(boxes[0].yaw, truth.yaw);
  EXPECT_DOUBLE_EQ(boxes[0].length, truth.length);
  EXPECT_DOUBLE_EQ(boxes[0].width, truth.width);
}

TEST(PointRefine, AHiddenFaceKeepsTheNetworksEstimate) {
  // Straight ahead, seen end-on: the rear fixes the position along the car; across it, the sensor is within the
  // car's width, so no side is seen and the lateral error stays.
  const Box truth = carBox(15, 0, 0);
  const PointCloud cloud = visibleFaces(truth);
  std::vector<Box> boxes = {moved(truth, -0.3, 0.2)};
  refineBoxesFromPoints(cloud, &boxes, carsOnly());
  EXPECT_NEAR(boxes[0].x, truth.x, 0.01);
  EXPECT_NEAR(boxes[0].y, truth.y + 0.2, 1e-9);
}

TEST(PointRefine, EndOnTheVisibleFaceCentresTheHiddenAxis) {
  // The same end-on car with hidden_midpoint: the rear face spans the car's width, so its returns centre it across.
  const Box truth = carBox(15, 0, 0);
  const PointCloud cloud = visibleFaces(truth);
  PointRefineOptions o = carsOnly();
  o.hidden_midpoint = true;
  std::vector<Box> boxes = {moved(truth, -0.3, 0.2)};
  refineBoxesFromPoints(cloud, &boxes, o);
  EXPECT_NEAR(boxes[0].x, truth.x, 0.01);
  EXPECT_NEAR(boxes[0].y, truth.y, 0.01);
  EXPECT_DOUBLE_EQ(boxes[0].width, truth.width);
  // Seen a little off-axis the face is still centred; an axis whose face is seen keeps the face fit.
  const Box offset = carBox(15, 0.6, 0.02);
  boxes = {moved(offset, 0.2, -0.25)};
  refineBoxesFromPoints(visibleFaces(offset), &boxes, o);
  EXPECT_NEAR(boxes[0].x, offset.x, 0.01);
  EXPECT_NEAR(boxes[0].y, offset.y, 0.01);
}

TEST(PointRefine, GrowsASizeToHoldTheReturnsOfASideSeenWhole) {
  // Seen obliquely, the right side is seen from end to end: a box 0.2 m too short, its rear on the rear face, grows
  // forward to the front end of the side; a box too long is not shrunk (the side may be occluded).
  const Box truth = carBox(12, 6, 0.3);
  const PointCloud cloud = visibleFaces(truth);
  PointRefineOptions o = carsOnly();
  o.grow = true;
  Box shorter = moved(truth, -0.1, 0);
  shorter.length = truth.length - 0.2;
  std::vector<Box> boxes = {shorter};
  refineBoxesFromPoints(cloud, &boxes, o);
  EXPECT_NEAR(boxes[0].length, truth.length, 0.01);
  EXPECT_NEAR(boxes[0].x, truth.x, 0.01);
  EXPECT_NEAR(boxes[0].y, truth.y, 0.01);
  EXPECT_NEAR(boxes[0].width, truth.width, 1e-3);
  Box longer = moved(truth, 0.2, 0);
  longer.length = truth.length + 0.4;
  boxes = {longer};
  refineBoxesFromPoints(cloud, &boxes, o);
  EXPECT_DOUBLE_EQ(boxes[0].length, longer.length);
  // Without grow the length is the network's.
  boxes = {shorter};
  refineBoxesFromPoints(cloud, &boxes, carsOnly());
  EXPECT_DOUBLE_EQ(boxes[0].length, shorter.length);
}

TEST(PointRefine, FitsTheHeadingToTheOutlineOfTheReturns) {
  // Seen obliquely (an L of rear and side), the network's heading 12 degrees off: the fitted heading is within half
  // a degree, and the faces then put the box in place.
  const Box truth = carBox(14, 8, 0.4);
  const PointCloud cloud = visibleFaces(truth);
  PointRefineOptions o = carsOnly();
  o.heading_search_deg = 20;
  o.heading_step_deg = 0.5;
  Box off = moved(truth, 0.2, -0.15);
  off.yaw += 0.21;
  std::vector<Box> boxes = {off};
  refineBoxesFromPoints(cloud, &boxes, o);
  EXPECT_NEAR(boxes[0].yaw, truth.yaw, 0.5 * M_PI / 180);
  EXPECT_NEAR(boxes[0].x, truth.x, 0.05);
  EXPECT_NEAR(boxes[0].y, truth.y, 0.05);
  // Seen end-on (one straight face), off the other way: the face fixes the heading too.
  const Box end_on = carBox(16, 0.3, 0.05);
  Box end_off = end_on;
  end_off.yaw -= 0.15;
  boxes = {end_off};
  refineBoxesFromPoints(visibleFaces(end_on), &boxes, o);
  EXPECT_NEAR(boxes[0].yaw, end_on.yaw, 0.5 * M_PI / 180);
  // Without the search, the network's heading stays.
  boxes = {off};
  refineBoxesFromPoints(cloud, &boxes, carsOnly());
  EXPECT_DOUBLE_EQ(boxes[0].yaw, off.yaw);
}

// The difference of two headings as box axes (mod 180 deg), in [0, pi/2].
double axisError(double a, double b) {
  const double d = std::abs(std::remainder(a - b, M_PI));
  return std::min(d, M_PI - d);
}

TEST(PointRefine, HeadingAnyTurnsABoxLyingAcrossTheCar) {
  PointRefineOptions o = carsOnly();
  o.heading_search_deg = 7.5;
  o.heading_any = true;
  // The axis error (deg) of the refined box of the car `truth` when the network's heading is `off` radians away.
  auto errorDeg = [&](const Box& truth, double off) {
    Box guess = truth;
    guess.yaw += off;
    std::vector<Box> boxes = {guess};
    refineBoxesFromPoints(visibleFaces(truth), &boxes, o);
    return axisError(boxes[0].yaw, truth.yaw) * 180 / M_PI;
  };
  // A car seen from the side and the rear (an L), the network's box a quarter turn plus 10 degrees off: the L fixes
  // the axes, and the 4.4 m side, longer than the box's width, is the length.
  const Box l_shape = carBox(12, 6, 0.3);
  EXPECT_LT(errorDeg(l_shape, M_PI / 2 + 0.17), 1.0);
  // Seen broadside only (one 4.4 m face), 60 degrees off: turned onto the face.
  EXPECT_LT(errorDeg(carBox(0.2, 12, 0.0), 1.05), 1.0);
  // Seen end-on (one 1.8 m rear face, which fits the box either way), 30 degrees off: aligned with the face, the
  // axis nearer the network's kept, not turned across.
  EXPECT_LT(errorDeg(carBox(15, 0.2, 0.0), 0.52), 1.0);
  // Without heading_any, the search stays within heading_search_deg of the network's.
  o.heading_any = false;
  EXPECT_GT(errorDeg(l_shape, M_PI / 2 + 0.17), 60.0);
}

TEST(PointRefine, SetsTheTopFromTheHighestReturnsAndKeepsTheBottom) {
  const Box truth = carBox(8, -7, -1.2, 4.0, 1.7, 1.62);
  PointCloud cloud = visibleFaces(truth);
  // Ground returns inside the footprint are below the clearance and must not count.
  for (double u = -2; u <= 2; u += 0.1) {
    Point p;
    p.x = static_cast<float>(truth.x + u), p.y = static_cast<float>(truth.y), p.z = -1.73f;
    cloud.push_back(p);
  }
  Box guess = truth;
  guess.height = 1.35;
  guess.z = truth.bottom() + 0.5 * guess.height;
  std::vector<Box> boxes = {guess};
  refineBoxesFromPoints(cloud, &boxes, carsOnly());
  EXPECT_NEAR(boxes[0].height, truth.height, 0.01);
  EXPECT_NEAR(boxes[0].bottom(), truth.bottom(), 1e-9);

  // With a beam spacing, a top above the highest return by less than the slack (range x spacing) is kept.
  PointRefineOptions sparse_beams = carsOnly();
  sparse_beams.vertical_resolution_deg = 1.0;  // slack 0.19 m at 10.6 m
  Box taller = truth;
  taller.height = truth.height + 0.1;
  taller.z = truth.bottom() + 0.5 * taller.height;
  boxes = {taller};
  refineBoxesFromPoints(cloud, &boxes, sparse_beams);
  EXPECT_NEAR(boxes[0].height, taller.height, 1e-9);

  PointRefineOptions no_height = carsOnly();
  no_height.height = false;
  boxes = {guess};
  refineBoxesFromPoints(cloud, &boxes, no_height);
  EXPECT_DOUBLE_EQ(boxes[0].height, guess.height);
}

TEST(PointRefine, LeavesOtherClassesSparseObjectsAndFarMovesAlone) {
  const Box truth = carBox(10, 4, 0.1);
  const PointCloud cloud = visibleFaces(truth);
  Box cyclist = moved(truth, 0.3, 0.3);
  cyclist.label = ObjectClass::Cyclist;
  std::vector<Box> boxes = {cyclist};
  EXPECT_EQ(refineBoxesFromPoints(cloud, &boxes, carsOnly()), 0u);
  EXPECT_DOUBLE_EQ(boxes[0].x, cyclist.x);

  // Two returns only: below min_points.
  PointCloud sparse;
  sparse.points.assign(cloud.points.begin(), cloud.points.begin() + 2);
  boxes = {moved(truth, 0.3, 0.3)};
  EXPECT_EQ(refineBoxesFromPoints(sparse, &boxes, carsOnly()), 0u);
  EXPECT_DOUBLE_EQ(boxes[0].x, moved(truth, 0.3, 0.3).x);

  // The move along each axis is clamped to max_shift.
  PointRefineOptions o = carsOnly();
  o.max_shift = 0.1;
  const Box guess = moved(truth, 0.25, 0);
  boxes = {guess};
  refineBoxesFromPoints(cloud, &boxes, o);
  EXPECT_NEAR(std::hypot(boxes[0].x - guess.x, boxes[0].y - guess.y), 0.1, 1e-6);

  // Off by default; an empty cloud or NaN returns change nothing and do not throw.
  boxes = {guess};
  EXPECT_EQ(refineBoxesFromPoints(cloud, &boxes, PointRefineOptions()), 0u);
  EXPECT_EQ(refineBoxesFromPoints(PointCloud(), &boxes, carsOnly()), 0u);
  PointCloud nans;
  Point p;
  p.x = p.y = p.z = std::nanf("");
  nans.points.assign(10, p);
  EXPECT_EQ(refineBoxesFromPoints(nans, &boxes, carsOnly()), 0u);
  EXPECT_DOUBLE_EQ(boxes[0].x, guess.x);
}

TEST(PointRefine, StrayReturnsAreOutvotedByTheQuantile) {
  const Box truth = carBox(9, 9, 0.7);
  PointCloud cloud = visibleFaces(truth);
  // A few returns of a pole just outside the right side of the box (within the margin).
  const double c = std::cos(truth.yaw), s = std::sin(truth.yaw);
  for (int k = 0; k < 6; ++k) {
    Point p;
    p.x = static_cast<float>(truth.x + 0.5 * c + (0.5 * truth.width + 0.2) * s);
    p.y = static_cast<float>(truth.y + 0.5 * s - (0.5 * truth.width + 0.2) * c);
    p.z = static_cast<float>(truth.bottom() + 0.5 + 0.1 * k);
    cloud.push_back(p);
  }
  PointRefineOptions o = carsOnly();
  o.quantile = 0.9;
  std::vector<Box> boxes = {truth};
  refineBoxesFromPoints(cloud, &boxes, o);
  EXPECT_LT(std::hypot(boxes[0].x - truth.x, boxes[0].y - truth.y), 0.03);
}

TEST(PointRefine, PutsASmallObjectBehindTheCentroidOfItsReturns) {
  // A pedestrian-sized column of returns on the near half of a 0.3 m cylinder around (14, -6): their centroid lies
  // in front of the centre, by the offset the options give.
  const double cx = 14, cy = -6, radius = 0.15, bearing = std::atan2(cy, cx);
  PointCloud cloud;
  for (double z = -1.2; z < 0.0; z += 0.1)
    for (double a = -1.2; a <= 1.2; a += 0.2) {
      Point p;
      p.x = static_cast<float>(cx - radius * std::cos(bearing + a));
      p.y = static_cast<float>(cy - radius * std::sin(bearing + a));
      p.z = static_cast<float>(z);
      cloud.push_back(p);
    }
  double mx = 0, my = 0;
  for (const Point& p : cloud.points) mx += p.x, my += p.y;
  mx /= static_cast<double>(cloud.size()), my /= static_cast<double>(cloud.size());
  const double offset = std::hypot(cx - mx, cy - my);
  Box guess = carBox(cx + 0.12, cy + 0.08, 0.4, 0.8, 0.6, 1.75);
  guess.label = ObjectClass::Pedestrian;
  PointRefineOptions o;
  o.centroid = {{ObjectClass::Pedestrian, offset}};
  std::vector<Box> boxes = {guess};
  EXPECT_EQ(refineBoxesFromPoints(cloud, &boxes, o), 1u);
  EXPECT_NEAR(boxes[0].x, cx, 0.01);
  EXPECT_NEAR(boxes[0].y, cy, 0.01);
  EXPECT_DOUBLE_EQ(boxes[0].height, guess.height);  // only the centre moves
  EXPECT_DOUBLE_EQ(boxes[0].yaw, guess.yaw);
}

// A pole or a trunk runs on above the height of a person; nothing stands right above a person's head. A pedestrian box
// on a pole is removed, one on a person is kept, and so is one under a tree's crown or a bridge high above.
TEST(PointRefine, APedestrianBoxWithReturnsRightAboveItsTopIsRemoved) {
  // Sensor frame (ground at -1.73 m). A column of returns: a person (to 1.75 m) or a pole (to 4 m).
  auto column = [](double cx, double cy, double radius, double top, PointCloud* cloud) {
    for (double z = -1.5; z < top - 1.73; z += 0.1)
      for (double a = -1.0; a <= 1.0; a += 0.25)
        cloud->push_back({static_cast<float>(cx - radius * std::cos(std::atan2(cy, cx) + a)),
                          static_cast<float>(cy - radius * std::sin(std::atan2(cy, cx) + a)), static_cast<float>(z),
                          0.3f});
  };
  PointCloud cloud;
  column(12, 3, 0.2, 1.75, &cloud);   // a person
  column(15, -4, 0.12, 4.0, &cloud);  // a sign pole
  column(20, 6, 0.2, 1.75, &cloud);   // a person under a crown 3.2-5 m above the ground
  for (double x = 18.5; x < 21.5; x += 0.2)
    for (double y = 4.5; y < 7.5; y += 0.2) cloud.push_back({static_cast<float>(x), static_cast<float>(y), 1.6f, 0.2f});
  auto pedestrian = [](double x, double y) {
    Box b = carBox(x, y, 0.0, 0.7, 0.7, 1.75);
    b.label = ObjectClass::Pedestrian;
    b.z = -1.73 + 0.5 * 1.75;
    b.score = 0.8f;
    return b;
  };
  std::vector<Box> boxes = {pedestrian(12, 3), pedestrian(15, -4), pedestrian(20, 6)};
  PointRefineOptions o;
  o.clear_above = {ObjectClass::Pedestrian};
  EXPECT_EQ(refineBoxesFromPoints(cloud, &boxes, o), 1u);
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_DOUBLE_EQ(boxes[0].x, 12);
  EXPECT_DOUBLE_EQ(boxes[1].x, 20);
  // Other classes are not checked: a car box on the pole stays.
  std::vector<Box> car = {carBox(15, -4, 0.0)};
  car[0].z = -1.73 + 0.75;
  EXPECT_EQ(refineBoxesFromPoints(cloud, &car, o), 0u);
  EXPECT_EQ(car.size(), 1u);
}

TEST(HeadingFromVelocity, MovingBoxesOfTheListedClassesFaceTheirVelocity) {
  Box walker = carBox(5, 5, 0.0, 0.8, 0.6, 1.7);
  walker.label = ObjectClass::Pedestrian;
  walker.vx = -0.6, walker.vy = 0.6;  // 0.85 m/s towards the upper left
  Box standing = walker;
  standing.vx = 0.1, standing.vy = 0.0;  // below the speed: its heading stays
  Box car = carBox(10, 0, 0.2);
  car.vx = 0.0, car.vy = 5.0;  // cars are not listed
  std::vector<Box> boxes = {walker, standing, car};
  EXPECT_EQ(headingFromVelocity(&boxes, {{ObjectClass::Pedestrian, 0.3}}), 1u);
  EXPECT_NEAR(boxes[0].yaw, 3 * M_PI / 4, 1e-12);
  EXPECT_DOUBLE_EQ(boxes[1].yaw, 0.0);
  EXPECT_DOUBLE_EQ(boxes[2].yaw, 0.2);
  EXPECT_EQ(headingFromVelocity(&boxes, {}), 0u);
}

TEST(PointRefine, CalibratedScoresRiseWithTheReturnsThatHoldTheBox) {
  // Two cars scored alike by the network, at the same range: one seen whole, its returns 5 cm inside its faces, one
  // (behind a wall) without a return. score = sigmoid(w . [1, logit s, log(1 + n), r / 40, log(1 + n) r / 40,
  // logit s log(1 + n), a, a^2, e]) with a = |sin(heading - bearing)| and e the returns' median distance to a face.
  const Box seen = carBox(12, 6, 0.3), unseen = carBox(-12, -6, 0.3);
  const PointCloud cloud = visibleFaces(seen, 0.05);
  PointRefineOptions o;
  o.score_calibration = {{ObjectClass::Car, {-2.0, 1.0, 0.5, 0.0, 0.0, 0.0, 0.3, 0.0, -4.0}}};
  std::vector<Box> boxes = {seen, unseen};
  boxes[0].score = boxes[1].score = 0.7f;
  EXPECT_EQ(refineBoxesFromPoints(cloud, &boxes, o), 0u);  // nothing moved: only the scores are calibrated
  const double logit = std::log(0.7 / 0.3), n = static_cast<double>(cloud.size());
  const double aspect = std::abs(std::sin(0.3 - std::atan2(6.0, 12.0)));
  auto sigmoid = [](double z) { return 1 / (1 + std::exp(-z)); };
  EXPECT_NEAR(boxes[0].score, sigmoid(-2.0 + logit + 0.5 * std::log1p(n) + 0.3 * aspect - 4.0 * 0.05), 1e-4);
  EXPECT_NEAR(boxes[1].score, sigmoid(-2.0 + logit + 0.3 * aspect - 4.0 * PointRefineOptions::kMaxResidual), 1e-5);
  EXPECT_GT(boxes[0].score, boxes[1].score);
  EXPECT_DOUBLE_EQ(boxes[0].x, seen.x);
  // Returns 20 cm outside the faces fit the box worse than returns 5 cm inside them.
  const PointCloud loose = visibleFaces(seen, -0.2);
  std::vector<Box> off = {seen};
  off[0].score = 0.7f;
  refineBoxesFromPoints(loose, &off, o);
  EXPECT_LT(off[0].score, boxes[0].score);
  // Other classes keep their scores.
  std::vector<Box> people = {seen};
  people[0].label = ObjectClass::Pedestrian;
  refineBoxesFromPoints(cloud, &people, o);
  EXPECT_FLOAT_EQ(people[0].score, 0.9f);
}

TEST(PointRefine, OptionsAreReadFromYamlAndMistakesRefused) {
  const auto o = detectorOptionsFromYaml(
      "inference:\n  point_refine: {faces: [Car, Cyclist], quantile: 0.8, centroid: {Pedestrian: 0.1}}\n");
  ASSERT_EQ(o.inference.point_refine.faces.size(), 2u);
  EXPECT_EQ(o.inference.point_refine.faces[1], ObjectClass::Cyclist);
  EXPECT_DOUBLE_EQ(o.inference.point_refine.quantile, 0.8);
  ASSERT_EQ(o.inference.point_refine.centroid.size(), 1u);
  EXPECT_EQ(o.inference.point_refine.centroid[0].first, ObjectClass::Pedestrian);
  EXPECT_DOUBLE_EQ(o.inference.point_refine.centroid[0].second, 0.1);
  EXPECT_FALSE(o.inference.point_refine.hidden_midpoint);
  const auto m = detectorOptionsFromYaml("inference:\n  point_refine: {faces: [Car], hidden_midpoint: true, grow: true}\n");
  EXPECT_TRUE(m.inference.point_refine.hidden_midpoint);
  EXPECT_TRUE(m.inference.point_refine.grow);
  EXPECT_DOUBLE_EQ(m.inference.point_refine.heading_search_deg, 0);
  const auto f = detectorOptionsFromYaml(
      "inference:\n  point_refine: {faces: [Car], heading_search_deg: 15, heading_step_deg: 0.5}\n");
  EXPECT_DOUBLE_EQ(f.inference.point_refine.heading_search_deg, 15);
  EXPECT_DOUBLE_EQ(f.inference.point_refine.heading_step_deg, 0.5);
  EXPECT_FALSE(detectorOptionsFromYaml("inference: {}").inference.point_refine.enabled());
  const auto g = detectorOptionsFromYaml(
      "inference:\n  point_refine: {faces: [Car], score_calibration: {Car: [-1, 2, 0.5, 0.1, 0, 0.2, 0, 0, -3]}}\n");
  ASSERT_EQ(g.inference.point_refine.score_calibration.size(), 1u);
  EXPECT_EQ(g.inference.point_refine.score_calibration[0].first, ObjectClass::Car);
  EXPECT_DOUBLE_EQ(g.inference.point_refine.score_calibration[0].second[8], -3);
  EXPECT_TRUE(detectorOptionsFromYaml("inference: {point_refine: {score_calibration: {Car: [0, 1, 0, 0, 0, 0, 0, 0, 0]}}}")
                  .inference.point_refine.enabled());
  const auto h = detectorOptionsFromYaml("inference: {heading_from_velocity: {Pedestrian: 0.3}}");
  ASSERT_EQ(h.inference.heading_from_velocity.size(), 1u);
  EXPECT_DOUBLE_EQ(h.inference.heading_from_velocity[0].second, 0.3);
  EXPECT_THROW(detectorOptionsFromYaml("inference: {heading_from_velocity: {Pedestrian: -1}}"), std::runtime_error);
  EXPECT_THROW(detectorOptionsFromYaml("inference: {heading_from_velocity: {Walker: 1}}"), std::runtime_error);
  for (const std::string bad : {"faces: [Truck]", "centroid: {Truck: 0.1}", "centroid: {Car: 0.1}, faces: [Car]",
                                "centroid: {Pedestrian: 3}", "quantile: 0", "quantile: 1.5", "min_points: 0", "margn: 0.3",
                                "max_shift: -1", "heading_search_deg: 50",
                                "heading_step_deg: 0", "heading_min_points: 2", "heading_any: true",
                                "score_calibration: {Car: [1, 2]}", "score_calibration: {Truck: [0, 1, 0, 0, 0, 0, 0, 0, 0]}",
                                "score_calibration: {Car: [0, .nan, 0, 0, 0, 0, 0, 0, 0]}", "score_calibration: [1, 2]"}) {
    try {
      detectorOptionsFromYaml("inference:\n  point_refine: {" + bad + "}\n");
      FAIL() << bad << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("inference.point_refine"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace ret3d
