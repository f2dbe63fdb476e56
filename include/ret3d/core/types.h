// Core value types shared by every layer: object classes, 3D boxes and point clouds.
// Conventions (ARCHITECTURE.md): REP 103 frames, metres, radians; a box is its geometric centre, length along the
// heading, width, height, yaw about z counter-clockwise from x in (-pi, pi].
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace ret3d {

// Values match the label constants of msg/Object3D.msg.
enum class ObjectClass : std::uint8_t { Unknown = 0, Car = 1, Pedestrian = 2, Cyclist = 3 };

// The three classes the package detects, in label order.
inline constexpr std::array<ObjectClass, 3> kDetectedClasses = {ObjectClass::Car, ObjectClass::Pedestrian,
                                                                ObjectClass::Cyclist};

// "Car", "Pedestrian", "Cyclist" or "Unknown".
const char* className(ObjectClass c);
// Inverse of className for the three detected classes (exact, case-sensitive); nullopt otherwise.
std::optional<ObjectClass> classFromName(std::string_view name);

struct Box {
  double x = 0, y = 0, z = 0;                  // geometric centre
  double length = 0, width = 0, height = 0;    // along heading, across, up
  double yaw = 0;                              // (-pi, pi]
  double vx = 0, vy = 0;                       // velocity over ground, m/s, same frame as the centre
  float score = 1.0f;
  ObjectClass label = ObjectClass::Unknown;
  std::uint32_t track_id = 0;                  // 0 = none
  std::uint32_t num_points = 0;                // points inside (0 = unknown or none)

  Eigen::Vector3d center() const { return {x, y, z}; }
  double bottom() const { return z - 0.5 * height; }
  double top() const { return z + 0.5 * height; }
};

// One LiDAR return. Laid out as 4 consecutive floats, so a vector of points is an N x 4 float matrix
// (and the KITTI velodyne .bin layout).
struct Point {
  float x = 0, y = 0, z = 0;
  float intensity = 0;  // normalised to [0, 1]
};
static_assert(sizeof(Point) == 4 * sizeof(float), "Point must be 4 packed floats");

struct PointCloud {
  std::vector<Point> points;
  std::vector<float> time;          // optional per-point time offset in seconds within the sweep; empty or size()
  std::vector<std::uint16_t> ring;  // optional per-point laser ring; empty or size()

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool hasTime() const { return !time.empty() && time.size() == points.size(); }
  bool hasRing() const { return !ring.empty() && ring.size() == points.size(); }
  void clear() {
    points.clear();
    time.clear();
    ring.clear();
  }
  // Appends a point; keeps time/ring aligned when they are in use.
  void push_back(const Point& p, float t = 0.0f, std::uint16_t r = 0, bool with_extras = false);
};

}  // namespace ret3d
