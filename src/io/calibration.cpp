// KITTI calibration files, in the object key style ("P2:", "R0_rect:", "Tr_velo_to_cam:", "Tr_imu_to_velo:") and the
// tracking devkit's style ("P2", "R_rect", "Tr_velo_cam", "Tr_imu_velo", with or without the colon).
#include <cmath>
#include <map>

#include "ret3d/io/kitti.h"
#include "text_fields.h"

namespace ret3d {
namespace kitti {
namespace {

enum class Key { P0, P1, P2, P3, R0_rect, Tr_velo_to_cam, Tr_imu_to_velo };

struct KeyInfo {
  Key key;
  const char* canonical;  // object-style name, used in messages
  int count;              // numbers expected
};

// Both key styles; other keys (e.g. Tr_cam_to_road) are ignored.
const std::map<std::string, KeyInfo, std::less<>>& keyTable() {
  static const std::map<std::string, KeyInfo, std::less<>> table = {
      {"P0", {Key::P0, "P0", 12}},
      {"P1", {Key::P1, "P1", 12}},
      {"P2", {Key::P2, "P2", 12}},
      {"P3", {Key::P3, "P3", 12}},
      {"R0_rect", {Key::R0_rect, "R0_rect", 9}},
      {"R_rect", {Key::R0_rect, "R0_rect", 9}},
      {"Tr_velo_to_cam", {Key::Tr_velo_to_cam, "Tr_velo_to_cam", 12}},
      {"Tr_velo_cam", {Key::Tr_velo_to_cam, "Tr_velo_to_cam", 12}},
      {"Tr_imu_to_velo", {Key::Tr_imu_to_velo, "Tr_imu_to_velo", 12}},
      {"Tr_imu_velo", {Key::Tr_imu_to_velo, "Tr_imu_to_velo", 12}},
  };
  return table;
}

Eigen::Matrix<double, 3, 4> rows34(const std::vector<double>& v) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = v[4 * r + c];
  return m;
}

Eigen::Isometry3d isometry34(const std::vector<double>& v) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.matrix().topRows<3>() = rows34(v);
  return t;
}

void appendValues(std::string& s, const char* key, const double* begin, int n) {
  s += key;
  s += ':';
  for (int i = 0; i < n; ++i) {
    s += ' ';
    detail::appendScientific(s, begin[i], 12);  // KITTI's own format (%.12e)
  }
  s += '\n';
}

void appendMatrix34(std::string& s, const char* key, const Eigen::Matrix<double, 3, 4>& m) {
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> rm = m;
  appendValues(s, key, rm.data(), 12);
}

}  // namespace

Eigen::Matrix4d Calibration::veloToRectMatrix() const {
  Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
  r.topLeftCorner<3, 3>() = R0_rect;
  return r * velo_to_cam.matrix();
}

Eigen::Vector3d Calibration::veloToRect(const Eigen::Vector3d& p) const {
  return (veloToRectMatrix() * p.homogeneous()).head<3>();
}

// The file's matrices are rounded to 7 digits and so are not exactly orthonormal: the inverse is taken in general
// (not as a transpose), which keeps veloToRect and rectToVelo exact inverses of each other.
Eigen::Vector3d Calibration::rectToVelo(const Eigen::Vector3d& p) const {
  return (veloToRectMatrix().inverse() * p.homogeneous()).head<3>();
}

std::optional<Eigen::Vector2d> Calibration::projectRect(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d uvw = P2 * p.homogeneous();
  if (p.z() <= 0.0 || uvw.z() <= 0.0) return std::nullopt;
  return Eigen::Vector2d(uvw.x() / uvw.z(), uvw.y() / uvw.z());
}

BevWedge imageRegionWedge(const Calibration& calib, double u_min, double u_max, double v_min, double v_max,
                          double margin) {
  const Eigen::Matrix3d A = calib.P2.leftCols<3>();
  if (std::abs(A.determinant()) < 1e-12) throw std::invalid_argument("imageRegionWedge: P2 is singular");
  const Eigen::Matrix3d A_inv = A.inverse();
  const Eigen::Vector3d centre = -A_inv * calib.P2.col(3);  // camera 2's centre, rectified frame
  const Eigen::Vector2d apex = calib.rectToVelo(centre).head<2>();
  auto bevRay = [&](double u, double v) {
    const Eigen::Vector3d d = A_inv * Eigen::Vector3d(u, v, 1.0);
    return Eigen::Vector2d((calib.rectToVelo(centre + d).head<2>() - apex).normalized());
  };
  const Eigen::Vector2d mid = bevRay(0.5 * (u_min + u_max), 0.5 * (v_min + v_max));
  auto angle = [&](const Eigen::Vector2d& r) { return std::atan2(mid.x() * r.y() - mid.y() * r.x(), mid.dot(r)); };
  // Per side, the ray farthest from the middle one (the side's sign decided by the middle row's ray).
  auto widest = [&](double u) {
    const double side = angle(bevRay(u, 0.5 * (v_min + v_max))) >= 0 ? 1.0 : -1.0;
    Eigen::Vector2d best = bevRay(u, v_min);
    for (double v : {0.5 * (v_min + v_max), v_max}) {
      const Eigen::Vector2d r = bevRay(u, v);
      if (side * angle(r) > side * angle(best)) best = r;
    }
    return best;
  };
  BevWedge w;
  w.apex = apex;
  w.ray_a = widest(u_min);
  w.ray_b = widest(u_max);
  w.margin = margin;
  return w;
}

Calibration readCalibration(const std::string& path) {
  std::map<Key, std::vector<double>> values;
  std::map<Key, int> seen_at;
  detail::forEachLine(path, [&](const auto& fields, const detail::Where& where) {
    std::string_view name = fields[0];
    if (!name.empty() && name.back() == ':') name.remove_suffix(1);
    const auto it = keyTable().find(name);
    if (it == keyTable().end()) return;
    const KeyInfo& info = it->second;
    if (const auto prev = seen_at.find(info.key); prev != seen_at.end()) {
      detail::fail(where, name, "given twice (first at line " + std::to_string(prev->second) + ")");
    }
    const int n = static_cast<int>(fields.size()) - 1;
    if (n != info.count) {
      detail::fail(where, name,
                   "expected " + std::to_string(info.count) + " numbers, found " + std::to_string(n));
    }
    std::vector<double> v(n);
    for (int i = 0; i < n; ++i) {
      const std::string field = std::string(name) + " (value " + std::to_string(i + 1) + " of " +
                                std::to_string(n) + ")";
      v[i] = detail::parseDouble(fields[i + 1], where, field);
    }
    values[info.key] = std::move(v);
    seen_at[info.key] = where.line;
  });

  const auto require = [&](Key k, const char* name, const char* alias) -> const std::vector<double>& {
    const auto it = values.find(k);
    if (it == values.end()) {
      detail::fail({path, 0}, name,
                   std::string("required key missing") + (alias ? std::string(" (also read as '") + alias + "')" : ""));
    }
    return it->second;
  };
  Calibration c;
  c.P2 = rows34(require(Key::P2, "P2", nullptr));
  const auto& r0 = require(Key::R0_rect, "R0_rect", "R_rect");
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) c.R0_rect(r, col) = r0[3 * r + col];
  c.velo_to_cam = isometry34(require(Key::Tr_velo_to_cam, "Tr_velo_to_cam", "Tr_velo_cam"));
  if (const auto it = values.find(Key::Tr_imu_to_velo); it != values.end()) c.imu_to_velo = isometry34(it->second);
  const Key pk[4] = {Key::P0, Key::P1, Key::P2, Key::P3};
  for (int k = 0; k < 4; ++k) {
    const auto it = values.find(pk[k]);
    c.P[k] = it != values.end() ? rows34(it->second) : Eigen::Matrix<double, 3, 4>::Zero();
  }
  // The package inverts these (camera rays, rectified camera -> LiDAR): a singular one would give NaN boxes and
  // wedges far from the file, so it is refused here, naming it.
  const auto invertible = [&](const Eigen::Matrix3d& m, Key k, const char* name) {
    if (!(std::abs(m.determinant()) >= 1e-12)) detail::fail({path, seen_at[k]}, name, "singular matrix");
  };
  invertible(c.P2.leftCols<3>(), Key::P2, "P2");
  invertible(c.R0_rect, Key::R0_rect, "R0_rect");
  invertible(c.velo_to_cam.linear(), Key::Tr_velo_to_cam, "Tr_velo_to_cam");
  return c;
}

void writeCalibration(const std::string& path, const Calibration& calib) {
  std::string s;
  appendMatrix34(s, "P0", calib.P[0]);
  appendMatrix34(s, "P1", calib.P[1]);
  appendMatrix34(s, "P2", calib.P2);  // P2 is the one the package uses; P[2] may be stale
  appendMatrix34(s, "P3", calib.P[3]);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r0 = calib.R0_rect;
  appendValues(s, "R0_rect", r0.data(), 9);
  appendMatrix34(s, "Tr_velo_to_cam", calib.velo_to_cam.matrix().topRows<3>());
  appendMatrix34(s, "Tr_imu_to_velo", calib.imu_to_velo.matrix().topRows<3>());
  detail::writeText(path, s);
}

Calibration defaultCalibration() {
  // KITTI tracking benchmark, sequences 0000-0013 (recorded 2011-09-26): public calibration constants.
  const std::vector<double> p0 = {7.215377e+02, 0.0, 6.095593e+02, 0.0, 0.0, 7.215377e+02, 1.728540e+02, 0.0,
                                  0.0, 0.0, 1.0, 0.0};
  const std::vector<double> p1 = {7.215377e+02, 0.0, 6.095593e+02, -3.875744e+02, 0.0, 7.215377e+02, 1.728540e+02,
                                  0.0, 0.0, 0.0, 1.0, 0.0};
  const std::vector<double> p2 = {7.215377e+02, 0.0, 6.095593e+02, 4.485728e+01, 0.0, 7.215377e+02, 1.728540e+02,
                                  2.163791e-01, 0.0, 0.0, 1.0, 2.745884e-03};
  const std::vector<double> p3 = {7.215377e+02, 0.0, 6.095593e+02, -3.395242e+02, 0.0, 7.215377e+02, 1.728540e+02,
                                  2.199936e+00, 0.0, 0.0, 1.0, 2.729905e-03};
  const std::vector<double> r0 = {9.999239e-01, 9.837760e-03, -7.445048e-03, -9.869795e-03, 9.999421e-01,
                                  -4.278459e-03, 7.402527e-03, 4.351614e-03, 9.999631e-01};
  const std::vector<double> tr_velo_cam = {7.533745e-03, -9.999714e-01, -6.166020e-04, -4.069766e-03,
                                           1.480249e-02, 7.280733e-04,  -9.998902e-01, -7.631618e-02,
                                           9.998621e-01, 7.523790e-03,  1.480755e-02,  -2.717806e-01};
  const std::vector<double> tr_imu_velo = {9.999976e-01,  7.553071e-04, -2.035826e-03, -8.086759e-01,
                                           -7.854027e-04, 9.998898e-01, -1.482298e-02, 3.195559e-01,
                                           2.024406e-03,  1.482454e-02, 9.998881e-01,  -7.997231e-01};
  Calibration c;
  c.P = {rows34(p0), rows34(p1), rows34(p2), rows34(p3)};
  c.P2 = c.P[2];
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) c.R0_rect(r, col) = r0[3 * r + col];
  c.velo_to_cam = isometry34(tr_velo_cam);
  c.imu_to_velo = isometry34(tr_imu_velo);
  return c;
}

}  // namespace kitti
}  // namespace ret3d
