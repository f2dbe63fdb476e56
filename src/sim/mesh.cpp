#include "ret3d/sim/mesh.h"

#include <algorithm>
#include <cmath>

namespace ret3d {
namespace sim {

void TriangleMesh::clear() {
  vertices.clear();
  triangles.clear();
  surfaces.clear();
}

void TriangleMesh::append(const TriangleMesh& other, const Eigen::Isometry3f& T) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  vertices.reserve(vertices.size() + other.vertices.size());
  for (const auto& v : other.vertices) vertices.push_back(T * v);
  for (const auto& t : other.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  surfaces.insert(surfaces.end(), other.surfaces.begin(), other.surfaces.end());
}

void TriangleMesh::addTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                               Surface s) {
  const auto i = static_cast<std::uint32_t>(vertices.size());
  vertices.push_back(a);
  vertices.push_back(b);
  vertices.push_back(c);
  triangles.push_back({i, i + 1, i + 2});
  surfaces.push_back(s);
}

void TriangleMesh::addQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                           const Eigen::Vector3f& d, Surface s) {
  const auto i = static_cast<std::uint32_t>(vertices.size());
  vertices.push_back(a);
  vertices.push_back(b);
  vertices.push_back(c);
  vertices.push_back(d);
  triangles.push_back({i, i + 1, i + 2});
  triangles.push_back({i, i + 2, i + 3});
  surfaces.push_back(s);
  surfaces.push_back(s);
}

void TriangleMesh::addBox(const Eigen::Isometry3f& T, const Eigen::Vector3f& size, Surface s, bool bottom) {
  const Eigen::Vector3f h = 0.5f * size;
  auto p = [&](float sx, float sy, float sz) { return Eigen::Vector3f(T * Eigen::Vector3f(sx * h.x(), sy * h.y(), sz * h.z())); };
  addQuad(p(-1, -1, 1), p(1, -1, 1), p(1, 1, 1), p(-1, 1, 1), s);      // top
  if (bottom) addQuad(p(-1, -1, -1), p(-1, 1, -1), p(1, 1, -1), p(1, -1, -1), s);
  addQuad(p(1, -1, -1), p(1, 1, -1), p(1, 1, 1), p(1, -1, 1), s);      // +x
  addQuad(p(-1, 1, -1), p(-1, -1, -1), p(-1, -1, 1), p(-1, 1, 1), s);  // -x
  addQuad(p(1, 1, -1), p(-1, 1, -1), p(-1, 1, 1), p(1, 1, 1), s);      // +y
  addQuad(p(-1, -1, -1), p(1, -1, -1), p(1, -1, 1), p(-1, -1, 1), s);  // -y
}

void TriangleMesh::addBeam(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float thickness, Surface s) {
  const Eigen::Vector3f d = b - a;
  const float len = d.norm();
  if (len < 1e-6f) return;
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), d / len).toRotationMatrix();
  T.translation() = 0.5f * (a + b);
  addBox(T, Eigen::Vector3f(thickness, thickness, len), s);
}

void TriangleMesh::addCylinder(const Eigen::Isometry3f& T, float radius, float height, int segments, Surface s) {
  for (int i = 0; i < segments; ++i) {
    const float a0 = 2.0f * static_cast<float>(M_PI) * i / segments, a1 = 2.0f * static_cast<float>(M_PI) * (i + 1) / segments;
    const Eigen::Vector3f p0(radius * std::cos(a0), radius * std::sin(a0), 0), p1(radius * std::cos(a1), radius * std::sin(a1), 0);
    const Eigen::Vector3f up(0, 0, height);
    addQuad(T * p0, T * p1, T * Eigen::Vector3f(p1 + up), T * Eigen::Vector3f(p0 + up), s);
    addTriangle(T * up, T * Eigen::Vector3f(p0 + up), T * Eigen::Vector3f(p1 + up), s);
    addTriangle(T * Eigen::Vector3f::Zero(), T * p1, T * p0, s);
  }
}

void TriangleMesh::addEllipsoid(const Eigen::Isometry3f& T, const Eigen::Vector3f& r, int slices, int stacks, Surface s) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  for (int i = 0; i <= stacks; ++i) {
    const float phi = static_cast<float>(M_PI) * i / stacks - 0.5f * static_cast<float>(M_PI);
    for (int j = 0; j < slices; ++j) {
      const float th = 2.0f * static_cast<float>(M_PI) * j / slices;
      vertices.push_back(T * Eigen::Vector3f(r.x() * std::cos(phi) * std::cos(th), r.y() * std::cos(phi) * std::sin(th),
                                             r.z() * std::sin(phi)));
    }
  }
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = base + i * slices + j, b = base + i * slices + (j + 1) % slices;
      const std::uint32_t c = a + slices, d = b + slices;
      triangles.push_back({a, b, d});
      triangles.push_back({a, d, c});
      surfaces.push_back(s);
      surfaces.push_back(s);
    }
  }
}

void TriangleMesh::addExtrusion(const std::vector<Eigen::Vector2f>& profile, float z0, float w0, float z1, float w1,
                                const Eigen::Isometry3f& T, Surface s) {
  const std::size_t n = profile.size();
  if (n < 3) return;
  auto hw = [&](float z) {
    const float t = (z1 > z0) ? std::clamp((z - z0) / (z1 - z0), 0.0f, 1.0f) : 0.0f;
    return w0 + t * (w1 - w0);
  };
  auto left = [&](std::size_t i) { return Eigen::Vector3f(T * Eigen::Vector3f(profile[i].x(), hw(profile[i].y()), profile[i].y())); };
  auto right = [&](std::size_t i) { return Eigen::Vector3f(T * Eigen::Vector3f(profile[i].x(), -hw(profile[i].y()), profile[i].y())); };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    addQuad(right(i), right(j), left(j), left(i), s);
  }
  // Side caps: a fan from the profile's centroid (the profiles used are star-shaped around it).
  Eigen::Vector2f c = Eigen::Vector2f::Zero();
  for (const auto& p : profile) c += p;
  c /= static_cast<float>(n);
  const Eigen::Vector3f cl = T * Eigen::Vector3f(c.x(), hw(c.y()), c.y()), cr = T * Eigen::Vector3f(c.x(), -hw(c.y()), c.y());
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    addTriangle(cl, left(j), left(i), s);
    addTriangle(cr, right(i), right(j), s);
  }
}

Eigen::AlignedBox3f TriangleMesh::bounds() const {
  Eigen::AlignedBox3f b;
  for (const auto& v : vertices) b.extend(v);
  return b;
}

}  // namespace sim
}  // namespace ret3d
