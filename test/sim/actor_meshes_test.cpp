#include "ret3d/sim/actor_meshes.h"

#include <gtest/gtest.h>

#include "ret3d/sim/actors.h"
#include "ret3d/sim/random.h"

namespace ret3d {
namespace sim {
namespace {

ActorSurfaces plain() {
  ActorSurfaces s;
  return s;
}

TEST(ActorMeshes, CarBodiesFillTheirBoxWithTheMargin) {
  for (CarBody body : {CarBody::Sedan, CarBody::Hatchback, CarBody::Suv, CarBody::Van}) {
    const double L = 4.2, W = 1.7, H = 1.55;
    const TriangleMesh m = carMesh(body, L, W, H, plain());
    const Eigen::AlignedBox3f b = m.bounds();
    EXPECT_GT(m.size(), 50u) << bodyName(body);
    // Inside the box (x, y centred, z from the ground), at most a few millimetres beyond the margin.
    EXPECT_LE(b.max().x(), 0.5 * L - kLabelMargin + 0.01) << bodyName(body);
    EXPECT_GE(b.min().x(), -0.5 * L + kLabelMargin - 0.01) << bodyName(body);
    EXPECT_LE(b.max().y(), 0.5 * W - kLabelMargin + 0.01) << bodyName(body);
    EXPECT_GE(b.min().y(), -0.5 * W + kLabelMargin - 0.01) << bodyName(body);
    EXPECT_GE(b.min().z(), -1e-4) << bodyName(body);
    EXPECT_LE(b.max().z(), H - kLabelMargin + 0.01) << bodyName(body);
    // And it fills it: not a toy box inside a big label.
    EXPECT_GT(b.sizes().x(), L - 2 * kLabelMargin - 0.02) << bodyName(body);
    EXPECT_GT(b.sizes().z(), H - kLabelMargin - 0.3) << bodyName(body);
  }
}

TEST(ActorMeshes, CarSizesAverageKittiCar) {
  Rng rng(7);
  SimConfig c;
  c.materials = defaultMaterials();
  double l = 0, w = 0, h = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    Actor a;
    drawCar(a, c, rng);
    l += a.length;
    w += a.width;
    h += a.height;
  }
  EXPECT_NEAR(l / n, 3.9, 0.15);
  EXPECT_NEAR(w / n, 1.6, 0.08);
  EXPECT_NEAR(h / n, 1.56, 0.06);
}

TEST(ActorMeshes, PedestrianWalksAndCyclistPedals) {
  // Over a gait cycle the legs swing: the mesh's length changes, its height does not.
  double lmin = 1e9, lmax = 0;
  for (int k = 0; k < 16; ++k) {
    const Eigen::AlignedBox3f b = pedestrianMesh({1.75, 0.45}, 2 * M_PI * k / 16, 0.4, plain()).bounds();
    lmin = std::min(lmin, static_cast<double>(b.sizes().x()));
    lmax = std::max(lmax, static_cast<double>(b.sizes().x()));
    EXPECT_NEAR(b.max().z(), 1.75, 0.06);
    EXPECT_NEAR(b.sizes().y(), 0.55, 0.12);
  }
  EXPECT_GT(lmax - lmin, 0.2);
  EXPECT_NEAR(lmax, 0.8, 0.2);
  // Standing, the build shows behind the feet (the toes reach furthest forward): half of a deeper chest, a backpack.
  auto back = [](const PersonShape& p) {
    return -static_cast<double>(pedestrianMesh(p, 0, 0, plain()).bounds().min().x());
  };
  EXPECT_NEAR(back({1.75, 0.45, 0.34}) - back({1.75, 0.45, 0.30}), 0.02, 0.003);
  EXPECT_NEAR(back({1.75, 0.45, 0.30, true}) - back({1.75, 0.45, 0.30}), 0.14, 0.01);
  const Eigen::AlignedBox3f c = cyclistMesh(RiderShape{}, 0.3, plain()).bounds();
  EXPECT_NEAR(c.sizes().x(), 1.78 - 2 * kLabelMargin, 0.08);
  EXPECT_NEAR(c.max().z(), 1.7, 0.12);
  EXPECT_NEAR(c.sizes().y(), 0.6, 0.12);
  // The build shows: handlebars set the width, the lean the height.
  RiderShape road, city;
  road.bar_width = 0.40, road.lean = 0.95;
  city.bar_width = 0.64, city.lean = 0.30;
  const Eigen::AlignedBox3f r = cyclistMesh(road, 0.3, plain()).bounds(), u = cyclistMesh(city, 0.3, plain()).bounds();
  EXPECT_NEAR(u.sizes().y() - r.sizes().y(), 0.17, 0.04);
  EXPECT_GT(u.max().z() - r.max().z(), 0.08);
}

}  // namespace
}  // namespace sim
}  // namespace ret3d
