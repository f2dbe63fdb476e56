// Cars of every paint and the detection floor, stop-and-go queues, hills, and roadside structures of many sizes
// (docs/SIMULATOR.md "Paints and the detection floor", "Queues", "Hills", "Roadside structures").
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "ret3d/sim/actors.h"
#include "ret3d/sim/ray_caster.h"
#include "ret3d/sim/scene.h"
#include "ret3d/sim/simulator.h"
#include "support/sim_info.h"
#include "support/test_util.h"

namespace ret3d {
namespace sim {
namespace {

SimConfig preset(const std::string& name) {
  return loadSimConfig(std::string(RET3D_SOURCE_DIR) + "/config/sim/" + name + ".yaml");
}

// What becomes of the rays hitting a sedan whose paint has `reflectivity`, its rear 10 m ahead of the sensor on flat
// ground: the fraction that return nothing or read intensity 0. `paint_only`: only the rays 5.5-8 degrees down, which
// hit its painted rear below the rear window (the sensor, 1.73 m up, sees its glass from above).
double darkFraction(const SensorModel& sensor, const SimConfig& cfg, float reflectivity, std::size_t* hits,
                    bool paint_only = true) {
  TriangleMesh ground;
  Surface road;
  road.reflectivity = 0.28f;
  ground.addQuad({-100, -100, -1.73f}, {100, -100, -1.73f}, {100, 100, -1.73f}, {-100, 100, -1.73f}, road);
  Rng rng(3);
  ActorSurfaces s;
  s.paint = drawSurface(cfg, "paint", rng);
  s.paint.reflectivity = reflectivity;
  s.glass = drawSurface(cfg, "car_glass", rng);
  s.tire = drawSurface(cfg, "tire", rng);
  s.plate = drawSurface(cfg, "plate", rng);
  RayCaster caster(sensor, 2);
  caster.setStatic(ground);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(12.1, 0, -1.73);  // a 4.2 m car: its rear at 10 m
  caster.setActor(0, carMesh(CarBody::Sedan, 4.2, 1.75, 1.45, s), pose, true);
  caster.commit();
  const Sweep sw = caster.cast(Eigen::Isometry3d::Identity(), 11, 0);
  std::size_t n = 0, dark = 0;
  for (std::size_t slot = 0; slot < sw.size(); ++slot) {
    const double el = sensor.elevation_deg[slot % sw.beams];
    if (sw.actor[slot] != 0 || (paint_only && (el < -8.0 || el > -5.5))) continue;
    ++n;
    dark += !sw.returned[slot] || sw.points[slot].intensity == 0.0f;
  }
  *hits = n;
  return n ? static_cast<double>(dark) / n : 0.0;
}

TEST(Paint, BlackCarsReturnLittleOrZeroIntensityWhereBrightOnesDoNot) {
  const SimConfig cfg = preset("urban_street");
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  sensor.ego_body_box.clear();
  std::size_t black_hits = 0, white_hits = 0;
  const double black = darkFraction(sensor, cfg, 0.03f, &black_hits);
  const double white = darkFraction(sensor, cfg, 0.6f, &white_hits);
  EXPECT_GT(black_hits, 200u);
  EXPECT_EQ(black_hits, white_hits);  // the same rays reach it
  EXPECT_GT(black, 0.85);
  EXPECT_LT(white, 0.25);  // the sensor's base drop-out and the near zero-intensity returns
  // The whole car, glass included: the glass is dark whatever the paint, the paint makes the difference.
  const double black_all = darkFraction(sensor, cfg, 0.03f, &black_hits, false);
  const double white_all = darkFraction(sensor, cfg, 0.6f, &white_hits, false);
  EXPECT_GT(black_all, 0.85);
  EXPECT_LT(white_all, 0.6);
  EXPECT_GT(black_all - white_all, 0.3);
  // Without the floor the black car would be bright enough to read (the floor does it, not the noise).
  sensor.weak_return_zero_below = 0;
  sensor.zero_intensity_below = 0;
  std::size_t hits = 0;
  EXPECT_LT(darkFraction(sensor, cfg, 0.03f, &hits), 0.5);
}

TEST(Paint, DetectionFloorZeroesThenDropsWeakerSignals) {
  SensorModel sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  for (const char* other : {"vlp32c", "os1_64"}) {  // one intensity model, one floor
    const SensorModel o = sensorByName(other, RET3D_SOURCE_DIR);
    EXPECT_EQ(o.weak_return_zero_below, sensor.weak_return_zero_below) << other;
    EXPECT_EQ(o.weak_return_lost_below, sensor.weak_return_lost_below) << other;
  }
  ASSERT_GT(sensor.weak_return_zero_below, sensor.weak_return_lost_below);
  EXPECT_FALSE(weakReturn(sensor, 0.3).zero);
  EXPECT_EQ(weakReturn(sensor, 0.3).lost, 0.0);
  const double mid = 0.5 * (sensor.weak_return_zero_below + sensor.weak_return_lost_below);
  EXPECT_TRUE(weakReturn(sensor, mid).zero);
  EXPECT_NEAR(weakReturn(sensor, mid).lost, 0.5, 1e-9);
  EXPECT_EQ(weakReturn(sensor, 0.5 * sensor.weak_return_lost_below).lost, 1.0);
}

TEST(Paint, CarColoursIncludeAQuarterDark) {
  const SimConfig cfg = preset("urban_street");
  Rng rng(5);
  int dark = 0, bright = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double r = drawPaint(cfg, rng);
    ASSERT_GT(r, 0.0);
    ASSERT_LE(r, 1.0);
    dark += r <= 0.06;
    bright += r >= 0.45;
  }
  EXPECT_NEAR(dark / static_cast<double>(n), 0.28, 0.03);
  EXPECT_NEAR(bright / static_cast<double>(n), 0.28, 0.03);
}

TEST(Queue, ALabelledCarStandsThreeToEightMetresAheadInMostFrames) {
  test::TempDir out;
  SimOptions o;
  o.config = preset("queue");
  ASSERT_EQ(o.config.traffic.queue.probability, 1.0);
  ASSERT_EQ(o.config.road.lanes_per_direction, 2);  // the urban street it is based on, with a lane beside
  o.sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  o.out_dir = out.path();
  o.frames = 20;
  o.threads = 2;
  int ahead_frames = 0, frames = 0;
  std::map<std::string, int> types;
  for (std::uint64_t seed : {31u, 32u}) {
    o.seed = seed;
    simulateSequence(o, 0);
    std::vector<bool> ahead(o.frames, false);
    for (const test::SimInfoRow& r : test::readSimInfo(out / "training/sim_info/0000.txt")) {
      ++types[r.type];
      if (r.type == "Truck") { EXPECT_GT(r.box.length, 5.5); }
      if (r.type == "Car") { EXPECT_LE(r.box.length, 5.2); }
      if (test::isCarAhead(r)) ahead[r.frame] = true;
    }
    ahead_frames += static_cast<int>(std::count(ahead.begin(), ahead.end(), true));
    frames += o.frames;
  }
  EXPECT_GE(ahead_frames, 0.8 * frames);
  // Trucks and vans around, labelled with KITTI's types.
  EXPECT_GT(types["Truck"] + types["Van"], 0);
}

// How far the labelled cars 20-45 m from the sensor stand from the flat ground under it (1.73 m below): the largest
// |bottom + 1.73| over two short drives of the preset.
double largestGroundOffsetAhead(const std::string& preset_name) {
  test::TempDir out;
  SimOptions o;
  o.config = preset(preset_name);
  o.sensor = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  o.out_dir = out.path();
  o.frames = 10;
  o.threads = 2;
  double largest = 0;
  for (std::uint64_t seed : {41u, 42u}) {
    o.seed = seed;
    simulateSequence(o, 0);
    for (const test::SimInfoRow& r : test::readSimInfo(out / "training/sim_info/0000.txt")) {
      const double range = std::hypot(r.box.x, r.box.y);
      if (r.type == "Car" && range > 20 && range < 45) largest = std::max(largest, std::abs(r.box.bottom() + 1.73));
    }
  }
  return largest;
}

TEST(Hills, CarsAheadStandAboveOrBelowTheSensorsFlatGroundOnlyOnHills) {
  const SimConfig hills = preset("hills");
  EXPECT_GT(hills.road.hill_amplitude.lo, 0.0);
  EXPECT_EQ(preset("urban_street").road.hill_amplitude.hi, 0.0);
  // Flat streets: the mount's height jitter and road roughness only (0.18 m on these drives).
  EXPECT_LT(largestGroundOffsetAhead("urban_street"), 0.35);
  // Hills: somewhere a car 20-45 m away stands half a metre or more off it (1.12 m on these drives).
  EXPECT_GT(largestGroundOffsetAhead("hills"), 0.5);
}

TEST(Roadside, TrunksPolesPostsAndBicyclesOfManySizesStandWhereRecorded) {
  const SimConfig cfg = preset("urban_street");
  Rng rng(17);
  Scene scene;
  layoutRoads(scene, cfg, rng, 60);
  buildStaticGeometry(scene, cfg, rng, 80, {});
  std::map<Furniture::Kind, std::vector<const Furniture*>> by;
  for (const Furniture& f : scene.furniture) by[f.kind].push_back(&f);
  for (auto kind : {Furniture::Trunk, Furniture::LampPole, Furniture::SignPole, Furniture::Post, Furniture::Bollard,
                    Furniture::Bicycle})
    ASSERT_GE(by[kind].size(), 3u) << "kind " << kind;
  auto spread = [&](Furniture::Kind k, double Furniture::*field) {
    double lo = 1e9, hi = -1e9;
    for (const Furniture* f : by[k]) {
      lo = std::min(lo, f->*field);
      hi = std::max(hi, f->*field);
    }
    return std::make_pair(lo, hi);
  };
  const auto trunk = spread(Furniture::Trunk, &Furniture::radius);
  EXPECT_LT(trunk.first, 0.12);
  EXPECT_GT(trunk.second, 0.38);
  const auto post = spread(Furniture::Post, &Furniture::radius);
  EXPECT_LE(post.second, 0.08);
  const auto lamp = spread(Furniture::LampPole, &Furniture::height);
  EXPECT_GE(lamp.first, 5.0);
  EXPECT_LE(lamp.second, 9.0);
  const auto sign = spread(Furniture::SignPole, &Furniture::height);
  EXPECT_GT(sign.second - sign.first, 0.6);
  // Each trunk, pole and post is in the mesh where recorded: a level ray 1 m above the ground from 3 m away hits its
  // surface (6-7 sided cylinders: between the inscribed and the drawn radius), unless something stands in between.
  RayCaster caster(sensorByName("hdl64e", RET3D_SOURCE_DIR), 1);
  caster.setStatic(scene.mesh);
  caster.commit();
  int checked = 0, found = 0;
  for (const Furniture& f : scene.furniture) {
    if (f.kind == Furniture::Bicycle || f.height < 1.2) continue;
    const double z = scene.groundHeight(f.p.x(), f.p.y()) + 1.0;
    for (double a : {0.3, 2.4, 4.5}) {
      const Eigen::Vector3d dir(std::cos(a), std::sin(a), 0);
      const Eigen::Vector3d origin = Eigen::Vector3d(f.p.x(), f.p.y(), z) - 3.0 * dir;
      double t = 0;
      int actor = 0;
      ++checked;
      if (caster.intersect(origin, dir, 0.0, 3.0, &t, &actor) && t > 3.0 - f.radius - 0.03 &&
          t < 3.0 - 0.8 * f.radius + 0.03)
        ++found;
    }
  }
  EXPECT_GT(checked, 30);
  EXPECT_GT(found, 0.8 * checked);
}

}  // namespace
}  // namespace sim
}  // namespace ret3d
