#include "ret3d/sim/actor_meshes.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ret3d {
namespace sim {

const char* bodyName(CarBody b) {
  switch (b) {
    case CarBody::Sedan: return "sedan";
    case CarBody::Hatchback: return "hatchback";
    case CarBody::Suv: return "suv";
    case CarBody::Van: return "van";
    case CarBody::Truck: return "truck";
  }
  return "sedan";
}

namespace {

using V2 = Eigen::Vector2f;
using V3 = Eigen::Vector3f;

// Side profiles as fractions of length (x, -0.5 rear .. 0.5 front) and height (z, 0 .. 1), counter-clockwise:
// the lower body up to the belt line (painted), the cabin above it (glazed), and for vans a painted cargo box.
struct Profile {
  std::vector<V2> lower, cabin, cargo;
  float belt;        // belt line (fraction of height)
  float roof_front;  // roof extent (fractions of length), where the painted roof panel goes
  float roof_rear;
  float clearance;   // body bottom (fraction of height)
};

Profile profileOf(CarBody b) {
  switch (b) {
    case CarBody::Sedan:
      return {{{-0.5f, 0.12f}, {0.5f, 0.12f}, {0.5f, 0.40f}, {0.46f, 0.55f}, {0.20f, 0.62f}, {-0.38f, 0.62f},
               {-0.49f, 0.60f}, {-0.5f, 0.40f}},
              {{-0.38f, 0.62f}, {0.20f, 0.62f}, {0.05f, 1.0f}, {-0.25f, 1.0f}}, {}, 0.62f, 0.05f, -0.25f, 0.12f};
    case CarBody::Hatchback:
      return {{{-0.5f, 0.12f}, {0.5f, 0.12f}, {0.5f, 0.42f}, {0.46f, 0.56f}, {0.18f, 0.63f}, {-0.46f, 0.63f},
               {-0.5f, 0.45f}},
              {{-0.47f, 0.63f}, {0.18f, 0.63f}, {0.02f, 1.0f}, {-0.40f, 1.0f}}, {}, 0.63f, 0.02f, -0.40f, 0.12f};
    case CarBody::Suv:
      return {{{-0.5f, 0.16f}, {0.5f, 0.16f}, {0.5f, 0.48f}, {0.46f, 0.62f}, {0.25f, 0.66f}, {-0.5f, 0.66f}},
              {{-0.49f, 0.66f}, {0.25f, 0.66f}, {0.10f, 1.0f}, {-0.46f, 1.0f}}, {}, 0.66f, 0.10f, -0.46f, 0.16f};
    case CarBody::Van:
      return {{{-0.5f, 0.12f}, {0.5f, 0.12f}, {0.5f, 0.45f}, {0.44f, 0.58f}, {0.38f, 0.62f}, {-0.5f, 0.62f}},
              {{0.0f, 0.62f}, {0.38f, 0.62f}, {0.27f, 1.0f}, {0.0f, 1.0f}},
              {{-0.5f, 0.62f}, {0.0f, 0.62f}, {0.0f, 1.0f}, {-0.5f, 1.0f}}, 0.62f, 0.27f, -0.5f, 0.12f};
    case CarBody::Truck:
      // Chassis and cab below the belt, the cab's glazed upper half ahead of a cargo box the full height.
      return {{{-0.5f, 0.14f}, {0.5f, 0.14f}, {0.5f, 0.45f}, {-0.5f, 0.45f}},
              {{0.30f, 0.45f}, {0.5f, 0.45f}, {0.47f, 0.78f}, {0.30f, 0.78f}},
              {{-0.5f, 0.45f}, {0.27f, 0.45f}, {0.27f, 1.0f}, {-0.5f, 1.0f}}, 0.45f, 0.27f, -0.5f, 0.14f};
  }
  return profileOf(CarBody::Sedan);
}

std::vector<V2> scaled(const std::vector<V2>& p, float L, float H) {
  std::vector<V2> out;
  for (const auto& q : p) out.emplace_back(q.x() * L, q.y() * H);
  return out;
}

Eigen::Isometry3f translation(float x, float y, float z) {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.translation() = V3(x, y, z);
  return T;
}

}  // namespace

TriangleMesh carMesh(CarBody body, double length, double width, double height, const ActorSurfaces& s) {
  const float m = static_cast<float>(kLabelMargin);
  const float L = static_cast<float>(length) - 2 * m, W = static_cast<float>(width) - 2 * m;
  const float H = static_cast<float>(height) - m;
  const Profile p = profileOf(body);
  TriangleMesh mesh;
  const Eigen::Isometry3f I = Eigen::Isometry3f::Identity();
  const float belt = p.belt * H;
  // Lower body: full width; slight tumblehome of the cabin (0.94 -> 0.80 of the half width).
  mesh.addExtrusion(scaled(p.lower, L, H), 0, 0.5f * W, H, 0.5f * W, I, s.paint);
  mesh.addExtrusion(scaled(p.cabin, L, H), belt, 0.47f * W, H, 0.40f * W, I, s.glass);
  if (!p.cargo.empty()) mesh.addExtrusion(scaled(p.cargo, L, H), belt, 0.5f * W, H, 0.46f * W, I, s.paint);
  // Painted roof panel just above the glass top.
  const float rw = (p.cargo.empty() ? 0.40f : 0.46f) * W, rz = H + 0.002f;
  mesh.addQuad(V3(p.roof_rear * L, -rw, rz), V3(p.roof_front * L, -rw, rz), V3(p.roof_front * L, rw, rz),
               V3(p.roof_rear * L, rw, rz), s.paint);
  // Wheels: radius from the clearance and size; axles at 0.34 of the length from the centre.
  const float r = std::clamp(0.21f * H, 0.28f, 0.38f);
  const float tire_w = 0.2f;
  for (int ax = -1; ax <= 1; ax += 2) {
    for (int side = -1; side <= 1; side += 2) {
      Eigen::Isometry3f T = translation(ax * 0.34f * L, side * (0.5f * W - 0.5f * tire_w) - 0.5f * tire_w, r);
      T.rotate(Eigen::AngleAxisf(static_cast<float>(-M_PI / 2), V3::UnitX()));  // cylinder axis z -> y
      mesh.addCylinder(T, r, tire_w, 10, s.tire);
    }
  }
  // Licence plates, front and rear (retro-reflective).
  const float pz = std::max(p.clearance * H + 0.12f, 0.35f);
  for (int e = -1; e <= 1; e += 2) {
    const float x = e * (0.5f * L + 0.004f);
    mesh.addQuad(V3(x, -0.26f, pz - 0.06f), V3(x, 0.26f, pz - 0.06f), V3(x, 0.26f, pz + 0.06f), V3(x, -0.26f, pz + 0.06f),
                 s.plate);
  }
  return mesh;
}

TriangleMesh pedestrianMesh(const PersonShape& person, double phase, double swing, const ActorSurfaces& s) {
  const float H = static_cast<float>(person.stature), B = static_cast<float>(person.breadth);
  const float D = static_cast<float>(person.depth);
  const float sw = static_cast<float>(swing), ph = static_cast<float>(phase);
  TriangleMesh mesh;
  const float hip_z = 0.53f * H, shoulder_z = 0.81f * H, thigh = 0.245f * H, shin = 0.245f * H;
  const float hip_y = 0.055f * H;
  // Legs: hip flexion sin(phase), knee bends during swing (when the leg moves forward).
  for (int side = -1; side <= 1; side += 2) {
    const float p = ph + (side > 0 ? 0.0f : static_cast<float>(M_PI));
    const float hip = sw * std::sin(p);
    const float knee = sw * 1.6f * std::max(0.0f, std::cos(p));  // flexed while swinging forward
    const V3 h(0, side * hip_y, hip_z);
    const V3 k = h + V3(thigh * std::sin(hip), 0, -thigh * std::cos(hip));
    const float shin_a = hip - knee;
    const V3 a = k + V3(shin * std::sin(shin_a), 0, -shin * std::cos(shin_a));
    mesh.addBeam(h, k, 0.13f * H / 1.75f, s.clothing2);
    mesh.addBeam(k, a, 0.10f * H / 1.75f, s.clothing2);
    // Foot: from the ankle forward.
    Eigen::Isometry3f T = translation(a.x() + 0.06f, a.y(), std::max(a.z() - 0.02f, 0.04f));
    mesh.addBox(T, V3(0.25f, 0.09f, 0.08f), s.tire);
  }
  // Torso (a box as deep as the build, the arms beside it making up the breadth) and head.
  Eigen::Isometry3f T = translation(0, 0, 0.5f * (hip_z + shoulder_z) - 0.02f * H);
  const float arm = 0.10f * H / 1.75f;  // upper arm in a sleeve
  const float torso_w = B - 2 * arm;
  mesh.addBox(T, V3(D, torso_w, shoulder_z - hip_z + 0.03f * H), s.clothing);
  if (person.backpack) {
    mesh.addBox(translation(-0.5f * D - 0.07f, 0, shoulder_z - 0.14f * H), V3(0.14f, 0.30f, 0.40f), s.clothing2);
  }
  mesh.addBeam(V3(0, 0, shoulder_z), V3(0, 0, 0.88f * H), 0.07f * H, s.skin);
  mesh.addEllipsoid(translation(0.01f * H, 0, 0.935f * H), V3(0.058f * H, 0.05f * H, 0.065f * H), 8, 5, s.skin);
  // Arms swing opposite to the legs.
  const float upper = 0.17f * H, fore = 0.16f * H;
  for (int side = -1; side <= 1; side += 2) {
    const float p = ph + (side > 0 ? static_cast<float>(M_PI) : 0.0f);
    const float sh = 0.8f * sw * std::sin(p);
    const V3 a(0, side * 0.5f * (torso_w + arm), shoulder_z - 0.02f * H);
    const V3 e = a + V3(upper * std::sin(sh), 0, -upper * std::cos(sh));
    const float fa = sh + 0.3f * sw + 0.15f;
    const V3 w = e + V3(fore * std::sin(fa), 0, -fore * std::cos(fa));
    mesh.addBeam(a, e, arm, s.clothing);
    mesh.addBeam(e, w, 0.08f * H / 1.75f, s.clothing);
  }
  return mesh;
}

namespace {

// A bicycle's frame points for a bike Lb long (wheels included): hubs, bottom bracket, saddle, head tube, wheel radius.
struct BikeFrame {
  float r, wb;
  V3 rear, front, bb, seat, head;
};

BikeFrame bikeFrame(float Lb) {
  BikeFrame f;
  f.r = std::clamp(0.19f * Lb, 0.3f, 0.36f);
  f.wb = Lb - 2 * f.r;
  f.rear = V3(-0.5f * f.wb, 0, f.r);
  f.front = V3(0.5f * f.wb, 0, f.r);
  f.bb = V3(-0.05f * f.wb, 0, 0.3f);
  f.seat = V3(-0.22f * f.wb, 0, f.r + 0.58f);
  f.head = V3(0.38f * f.wb, 0, f.r + 0.52f);
  return f;
}

// Wheels (tyre rings of beams), frame tubes, handlebar and saddle; no cranks.
void addBicycle(TriangleMesh& mesh, const BikeFrame& f, float half_bar, const ActorSurfaces& s) {
  for (const V3& hub : {f.rear, f.front}) {
    const int n = 14;
    for (int i = 0; i < n; ++i) {
      const float a0 = 2 * static_cast<float>(M_PI) * i / n, a1 = 2 * static_cast<float>(M_PI) * (i + 1) / n;
      mesh.addBeam(hub + V3(f.r * std::cos(a0), 0, f.r * std::sin(a0)),
                   hub + V3(f.r * std::cos(a1), 0, f.r * std::sin(a1)), 0.05f, s.tire);
    }
    mesh.addBeam(hub + V3(0, -0.05f, 0), hub + V3(0, 0.05f, 0), 0.06f, s.metal);  // hub
  }
  mesh.addBeam(f.rear, f.bb, 0.035f, s.metal);
  mesh.addBeam(f.rear, f.seat, 0.03f, s.metal);
  mesh.addBeam(f.bb, f.seat, 0.04f, s.metal);
  mesh.addBeam(f.bb, f.head, 0.045f, s.metal);
  mesh.addBeam(f.seat + V3(0, 0, -0.05f), f.head, 0.04f, s.metal);
  mesh.addBeam(f.head, f.front, 0.04f, s.metal);
  const V3 bar = f.head + V3(0.02f, 0, 0.12f);
  mesh.addBeam(bar + V3(0, -half_bar, 0), bar + V3(0, half_bar, 0), 0.035f, s.metal);
  mesh.addBox(translation(f.seat.x(), 0, f.seat.z() + 0.03f), V3(0.25f, 0.12f, 0.05f), s.tire);
}

}  // namespace

TriangleMesh bicycleMesh(double length, double bar_width, const ActorSurfaces& s) {
  TriangleMesh mesh;
  const BikeFrame f = bikeFrame(static_cast<float>(length));
  addBicycle(mesh, f, 0.5f * static_cast<float>(bar_width), s);
  for (int side = -1; side <= 1; side += 2)  // cranks at rest, one up, one down
    mesh.addBeam(f.bb + V3(0, side * 0.12f, 0), f.bb + V3(0, side * 0.12f, side * 0.17f), 0.03f, s.metal);
  return mesh;
}

TriangleMesh cyclistMesh(const RiderShape& rider, double crank, const ActorSurfaces& s) {
  const float m = static_cast<float>(kLabelMargin);
  const float Lb = static_cast<float>(rider.length) - 2 * m, H = static_cast<float>(rider.stature);
  const float half_bar = 0.5f * static_cast<float>(rider.bar_width), lean = static_cast<float>(rider.lean);
  TriangleMesh mesh;
  const BikeFrame frame = bikeFrame(Lb);
  addBicycle(mesh, frame, half_bar, s);
  const V3 bb = frame.bb, seat = frame.seat, head = frame.head;
  const V3 bar = head + V3(0.02f, 0, 0.12f);
  // Rider: hips on the saddle, torso leaning to the bars, legs on the pedals (two-link inverse kinematics).
  const float thigh = 0.245f * H, shin = 0.25f * H, crank_r = 0.17f;
  const V3 hip = seat + V3(-0.03f, 0, 0.08f);
  for (int side = -1; side <= 1; side += 2) {
    const float c = static_cast<float>(crank) + (side > 0 ? 0.0f : static_cast<float>(M_PI));
    const V3 pedal = bb + V3(crank_r * std::cos(c), side * 0.12f, crank_r * std::sin(c));
    const V3 h = hip + V3(0, side * 0.1f, 0);
    mesh.addBeam(bb + V3(0, side * 0.12f, 0), pedal, 0.03f, s.metal);
    V3 d = pedal - h;
    const float dist = std::min(d.norm(), thigh + shin - 1e-3f);
    d.normalize();
    // Knee forward of the hip-pedal line, in the x-z plane.
    const float a = std::acos(std::clamp((thigh * thigh + dist * dist - shin * shin) / (2 * thigh * dist), -1.0f, 1.0f));
    const V3 perp(-d.z(), 0, d.x());  // d rotated +90 degrees about y: points forward-up when d points down
    V3 knee = h + thigh * (std::cos(a) * d + std::sin(a) * (perp.x() >= 0 ? perp : V3(-perp)));
    const V3 foot = h + dist * d;
    mesh.addBeam(h, knee, 0.13f * H / 1.75f, s.clothing2);
    mesh.addBeam(knee, foot, 0.10f * H / 1.75f, s.clothing2);
    mesh.addBox(translation(foot.x() + 0.04f, foot.y(), foot.z()), V3(0.24f, 0.09f, 0.07f), s.tire);
  }
  const float torso_len = 0.30f * H;
  const V3 shoulder = hip + torso_len * V3(std::sin(lean), 0, std::cos(lean));
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.translation() = 0.5f * (hip + shoulder);
  T.linear() = Eigen::AngleAxisf(lean, V3::UnitY()).toRotationMatrix();
  mesh.addBox(T, V3(0.13f * H, static_cast<float>(rider.breadth), torso_len + 0.06f), s.clothing);
  const V3 head_c = shoulder + V3(0.10f, 0, 0.16f);
  mesh.addEllipsoid(translation(head_c.x(), 0, head_c.z()), V3(0.11f, 0.09f, 0.12f), 8, 5, s.clothing);  // helmet
  for (int side = -1; side <= 1; side += 2) {
    const V3 sh = shoulder + V3(0, side * (0.5f * static_cast<float>(rider.breadth) + 0.03f), -0.02f);
    const V3 hand = bar + V3(0, side * (half_bar - 0.03f), 0);
    const V3 elbow = 0.5f * (sh + hand) + V3(-0.03f, side * 0.03f, -0.06f);
    mesh.addBeam(sh, elbow, 0.05f, s.clothing);
    mesh.addBeam(elbow, hand, 0.045f, s.skin);
  }
  return mesh;
}

}  // namespace sim
}  // namespace ret3d
