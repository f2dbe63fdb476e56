// Triangle meshes with a reflectivity and drop-out probability per triangle, and the primitives scenes and actors
// are built from (boxes, prisms, cylinders, ellipsoids, quads, extruded profiles).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ret3d {
namespace sim {

// What a ray hitting a triangle sees.
struct Surface {
  float reflectivity = 0.2f;
  float dropout = 0.0f;
  // Probability that a ray entering this surface returns from inside the volume it bounds (tree crowns, hedges), at a
  // depth drawn uniformly up to the next surface along the ray (at most kPorousDepth).
  float porosity = 0.0f;
};
constexpr float kPorousDepth = 3.0f;  // m

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Surface> surfaces;  // one per triangle

  std::size_t size() const { return triangles.size(); }
  void clear();
  void append(const TriangleMesh& other, const Eigen::Isometry3f& T = Eigen::Isometry3f::Identity());
  void addTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, Surface s);
  // A quad a-b-c-d (counter-clockwise seen from outside).
  void addQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3f& d,
               Surface s);
  // Axis-aligned box in the frame T (centre, full sizes), all six faces unless `bottom` is false.
  void addBox(const Eigen::Isometry3f& T, const Eigen::Vector3f& size, Surface s, bool bottom = true);
  // A box between two points with a square cross-section of side `thickness` (limbs, tubes, posts, rails).
  void addBeam(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float thickness, Surface s);
  // Cylinder along the frame's z from z=0 to z=height, `segments` sides, capped.
  void addCylinder(const Eigen::Isometry3f& T, float radius, float height, int segments, Surface s);
  // Ellipsoid with semi-axes r in frame T (latitude/longitude tessellation).
  void addEllipsoid(const Eigen::Isometry3f& T, const Eigen::Vector3f& r, int slices, int stacks, Surface s);
  // A prism: the closed polygon `profile` in the x-z plane (counter-clockwise seen from +y), extruded over
  // y in [-half_width(z), +half_width(z)], where half_width is linear in z between (z0, w0) and (z1, w1); capped.
  void addExtrusion(const std::vector<Eigen::Vector2f>& profile, float z0, float w0, float z1, float w1,
                    const Eigen::Isometry3f& T, Surface s);

  // Axis-aligned bounds of the vertices.
  Eigen::AlignedBox3f bounds() const;
};

}  // namespace sim
}  // namespace ret3d
