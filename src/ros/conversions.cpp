#include "ret3d/ros/conversions.h"

#include <sensor_msgs/PointField.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace {

using sensor_msgs::PointField;

constexpr bool kHostIsBigEndian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;

// PointField's datatypes 1 (INT8) to 8 (FLOAT64), in that order: name, bytes, largest positive value (the divisor
// of IntensityScaling::DatatypeRange; 1 for the float types).
struct DatatypeInfo {
  const char* name;
  std::size_t size;
  double max;
};
template <typename T>
constexpr double maxOf() {
  return static_cast<double>(std::numeric_limits<T>::max());
}
constexpr std::array<DatatypeInfo, 8> kDatatypes = {{{"int8", 1, maxOf<std::int8_t>()},
                                                     {"uint8", 1, maxOf<std::uint8_t>()},
                                                     {"int16", 2, maxOf<std::int16_t>()},
                                                     {"uint16", 2, maxOf<std::uint16_t>()},
                                                     {"int32", 4, maxOf<std::int32_t>()},
                                                     {"uint32", 4, maxOf<std::uint32_t>()},
                                                     {"float32", 4, 1.0},
                                                     {"float64", 8, 1.0}}};
static_assert(PointField::INT8 == 1 && PointField::UINT32 == 6 && PointField::FLOAT64 == 8);
constexpr DatatypeInfo kUnknownDatatype = {"unknown", 0, 1.0};

const DatatypeInfo& datatypeInfo(std::uint8_t datatype) {
  return datatype >= 1 && datatype <= kDatatypes.size() ? kDatatypes[datatype - 1] : kUnknownDatatype;
}
std::size_t datatypeSize(std::uint8_t datatype) { return datatypeInfo(datatype).size; }
double datatypeMax(std::uint8_t datatype) { return datatypeInfo(datatype).max; }
const char* datatypeName(std::uint8_t datatype) { return datatypeInfo(datatype).name; }

bool isFloat(std::uint8_t datatype) { return datatype == PointField::FLOAT32 || datatype == PointField::FLOAT64; }

// double -> float; values beyond float's range become +-inf (a plain cast of those is undefined behaviour).
float toFloat(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);
}

template <typename T>
T loadAs(const std::uint8_t* bytes) {
  T v;
  std::memcpy(&v, bytes, sizeof(T));
  return v;
}

// One field of the message, read from a point's bytes as a double in host byte order.
struct FieldReader {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  std::size_t size = 0;
  bool swap = false;

  double read(const std::uint8_t* point) const {
    std::uint8_t b[8];
    std::memcpy(b, point + offset, size);
    if (swap) std::reverse(b, b + size);
    switch (datatype) {
      case PointField::INT8:
        return loadAs<std::int8_t>(b);
      case PointField::UINT8:
        return loadAs<std::uint8_t>(b);
      case PointField::INT16:
        return loadAs<std::int16_t>(b);
      case PointField::UINT16:
        return loadAs<std::uint16_t>(b);
      case PointField::INT32:
        return loadAs<std::int32_t>(b);
      case PointField::UINT32:
        return loadAs<std::uint32_t>(b);
      case PointField::FLOAT32:
        return loadAs<float>(b);
      case PointField::FLOAT64:
        return loadAs<double>(b);
      default:
        return 0.0;
    }
  }
};

// The first of `names` present in the message, validated against point_step; nullopt when none is present.
std::optional<FieldReader> findField(const sensor_msgs::PointCloud2& msg, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    for (const auto& f : msg.fields) {
      if (f.name != name) continue;
      FieldReader r;
      r.name = f.name;
      r.offset = f.offset;
      r.datatype = f.datatype;
      r.size = datatypeSize(f.datatype);
      r.swap = static_cast<bool>(msg.is_bigendian) != kHostIsBigEndian;
      if (r.size == 0) {
        throw std::invalid_argument("PointCloud2 field '" + f.name + "' has unknown datatype " +
                                    std::to_string(static_cast<int>(f.datatype)));
      }
      if (static_cast<std::size_t>(f.offset) + r.size > msg.point_step) {
        std::ostringstream oss;
        oss << "PointCloud2 field '" << f.name << "' (" << datatypeName(f.datatype) << " at offset " << f.offset
            << ") extends past point_step " << msg.point_step;
        throw std::invalid_argument(oss.str());
      }
      return r;
    }
  }
  return std::nullopt;
}

// The message's sizes against each other and its data: a clear error naming the mismatch.
void checkCloudLayout(const sensor_msgs::PointCloud2& msg, const CloudConversionOptions& options) {
  const std::size_t width = msg.width, height = msg.height;
  const std::size_t n = width * height;
  if (msg.point_step == 0)
    throw std::invalid_argument("PointCloud2 has point_step 0 with " + std::to_string(n) + " points");
  if (msg.row_step < width * msg.point_step) {
    std::ostringstream oss;
    oss << "PointCloud2 row_step " << msg.row_step << " is smaller than width * point_step = " << width << " * "
        << msg.point_step;
    throw std::invalid_argument(oss.str());
  }
  const std::size_t needed = msg.row_step * (height - 1) + width * msg.point_step;
  if (msg.data.size() < needed) {
    std::ostringstream oss;
    oss << "PointCloud2 data holds " << msg.data.size() << " bytes but " << width << " x " << height
        << " points (point_step " << msg.point_step << ", row_step " << msg.row_step << ") need " << needed;
    throw std::invalid_argument(oss.str());
  }
  if (options.intensity_scaling == IntensityScaling::FixedScale && !(options.intensity_scale > 0.0)) {
    throw std::invalid_argument("CloudConversionOptions::intensity_scale must be > 0 for FixedScale");
  }
}

// The fields read: x, y, z (required), intensity, ring and time when present (and asked for).
struct CloudFields {
  FieldReader x, y, z;
  std::optional<FieldReader> intensity, ring, time;
};

CloudFields findCloudFields(const sensor_msgs::PointCloud2& msg, const CloudConversionOptions& options,
                            CloudConversionReport& rep) {
  const auto fx = findField(msg, {"x"});
  const auto fy = findField(msg, {"y"});
  const auto fz = findField(msg, {"z"});
  if (!fx || !fy || !fz) {
    std::string present;
    for (const auto& f : msg.fields) present += (present.empty() ? "" : ", ") + f.name;
    throw std::invalid_argument("PointCloud2 lacks field '" +
                                std::string(!fx   ? "x"
                                            : !fy ? "y"
                                                  : "z") +
                                "' (fields: " + (present.empty() ? "none" : present) + ")");
  }
  CloudFields f{*fx, *fy, *fz, findField(msg, {"intensity", "i", "reflectivity"}),
                options.keep_ring ? findField(msg, {"ring"}) : std::nullopt,
                options.keep_time ? findField(msg, {"time", "t", "timestamp"}) : std::nullopt};
  if (f.intensity) {
    rep.intensity_field = f.intensity->name;
  } else {
    rep.warnings.push_back("no intensity field (intensity, i or reflectivity): intensities set to 0");
  }
  if (f.ring) rep.has_ring = true;
  if (f.time) rep.time_field = f.time->name;
  return f;
}

// The points (raw intensities, rings) and raw times of the message, thinned to `kept` of its n points spread evenly,
// without the non-finite ones; returns the largest raw intensity.
double readPoints(const sensor_msgs::PointCloud2& msg, const CloudFields& f, std::size_t kept, PointCloud& cloud,
                  std::vector<double>& times, CloudConversionReport& rep) {
  const std::size_t width = msg.width, height = msg.height;
  const std::size_t n = width * height;
  // Input point k (row-major index) is read when floor(k * kept / n) steps up, which happens for exactly `kept` of the
  // n indices (128-bit products: k * kept may pass 2^64 for huge messages).
  const auto read = [&](std::size_t k) {
    return kept == n ||
           (static_cast<unsigned __int128>(k) * kept) / n != (static_cast<unsigned __int128>(k + 1) * kept) / n;
  };
  cloud.points.reserve(kept);
  if (f.time) times.reserve(kept);
  if (f.ring) cloud.ring.reserve(kept);
  double raw_max = 0.0;
  for (std::size_t row = 0; row < height; ++row) {
    const std::uint8_t* row_ptr = msg.data.data() + row * msg.row_step;
    for (std::size_t col = 0; col < width; ++col) {
      if (!read(row * width + col)) continue;
      const std::uint8_t* p = row_ptr + col * msg.point_step;
      // Finiteness is checked after the conversion to float: a float64 coordinate beyond float's range (1e300) is as
      // unusable as a NaN.
      Point pt;
      pt.x = toFloat(f.x.read(p));
      pt.y = toFloat(f.y.read(p));
      pt.z = toFloat(f.z.read(p));
      if (!std::isfinite(pt.x) || !std::isfinite(pt.y) || !std::isfinite(pt.z)) {
        ++rep.dropped_nonfinite;
        continue;
      }
      if (f.intensity) {
        const float v = toFloat(f.intensity->read(p));
        // A non-finite intensity is a sensor glitch on a valid point: keep the point, with intensity 0.
        pt.intensity = std::isfinite(v) ? v : 0.0f;
        raw_max = std::max(raw_max, static_cast<double>(pt.intensity));
      }
      cloud.points.push_back(pt);
      if (f.ring) {
        const double r = f.ring->read(p);
        cloud.ring.push_back(static_cast<std::uint16_t>(std::clamp(std::isfinite(r) ? r : 0.0, 0.0, 65535.0)));
      }
      if (f.time) {
        const double t = f.time->read(p);
        times.push_back(std::isfinite(t) ? t : 0.0);
      }
    }
  }
  return raw_max;
}

// Intensities into [0, 1] by the divisor the scaling asks for (recorded in the report).
void scaleIntensities(PointCloud& cloud, std::uint8_t datatype, double raw_max, const CloudConversionOptions& options,
                      CloudConversionReport& rep) {
  double divisor = 1.0;
  switch (options.intensity_scaling) {
    case IntensityScaling::Auto:
      divisor = isFloat(datatype) ? (raw_max > 1.0 ? raw_max : 1.0) : datatypeMax(datatype);
      break;
    case IntensityScaling::DatatypeRange:
      divisor = isFloat(datatype) ? 1.0 : datatypeMax(datatype);
      break;
    case IntensityScaling::ObservedMax:
      divisor = raw_max > 0.0 ? raw_max : 1.0;
      break;
    case IntensityScaling::FixedScale:
      divisor = options.intensity_scale;
      break;
  }
  rep.intensity_divisor = divisor;
  // Divided in double: 1 / divisor in float overflows for a tiny FixedScale divisor (0 * inf = NaN intensities).
  for (auto& pt : cloud.points) pt.intensity = static_cast<float>(std::clamp(pt.intensity / divisor, 0.0, 1.0));
}

// Per-point times as seconds within the sweep: integer times are nanoseconds (Ouster `t`), float times seconds
// (velodyne `time`); absolute stamps (e.g. Hesai's float64 `timestamp`) become offsets from the header stamp (or the
// earliest time when the stamp is 0).
void setPointTimes(PointCloud& cloud, const std::vector<double>& times, std::uint8_t datatype, double stamp) {
  const double to_seconds = isFloat(datatype) ? 1.0 : 1e-9;
  double origin = 0.0;
  const bool absolute = std::any_of(times.begin(), times.end(), [&](double t) { return t * to_seconds > 1e6; });
  if (absolute) {
    origin = stamp;
    if (origin == 0.0) origin = *std::min_element(times.begin(), times.end()) * to_seconds;
  }
  cloud.time.resize(times.size());
  for (std::size_t i = 0; i < times.size(); ++i) {
    const float t = toFloat(times[i] * to_seconds - origin);
    cloud.time[i] = std::isfinite(t) ? t : 0.0f;  // like a non-finite raw time: an offset beyond float's range
  }
}

}  // namespace

PointCloud toCloud(const sensor_msgs::PointCloud2& msg, const CloudConversionOptions& options,
                   CloudConversionReport* report) {
  CloudConversionReport local_report;
  CloudConversionReport& rep = report ? *report : local_report;
  rep = CloudConversionReport{};

  PointCloud cloud;
  const std::size_t n = static_cast<std::size_t>(msg.width) * msg.height;
  rep.input_points = n;
  // An empty message (even a default-constructed one without fields) is a valid empty scan.
  if (n == 0) return cloud;
  checkCloudLayout(msg, options);
  const CloudFields fields = findCloudFields(msg, options, rep);

  // Over the limit: `kept` of the n points, spread evenly.
  const std::size_t kept = options.max_points > 0 && n > options.max_points ? options.max_points : n;
  rep.thinned = kept < n;
  std::vector<double> times;
  const double raw_max = readPoints(msg, fields, kept, cloud, times, rep);
  rep.output_points = cloud.points.size();
  rep.raw_intensity_max = raw_max;
  if (fields.intensity) scaleIntensities(cloud, fields.intensity->datatype, raw_max, options, rep);
  if (fields.time) setPointTimes(cloud, times, fields.time->datatype, msg.header.stamp.toSec());
  return cloud;
}

sensor_msgs::PointCloud2 toPointCloud2(const PointCloud& cloud, const std_msgs::Header& header) {
  // The velodyne driver's packed layout (velodyne_pointcloud's PointXYZIR plus time).
  constexpr std::uint32_t kStep = 22;
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  msg.height = 1;
  msg.width = static_cast<std::uint32_t>(cloud.size());
  msg.is_bigendian = kHostIsBigEndian;
  msg.is_dense = true;
  msg.point_step = kStep;
  msg.row_step = kStep * msg.width;
  const auto addField = [&](const char* name, std::uint32_t offset, std::uint8_t datatype) {
    PointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = datatype;
    f.count = 1;
    msg.fields.push_back(f);
  };
  addField("x", 0, PointField::FLOAT32);
  addField("y", 4, PointField::FLOAT32);
  addField("z", 8, PointField::FLOAT32);
  addField("intensity", 12, PointField::FLOAT32);
  addField("ring", 16, PointField::UINT16);
  addField("time", 18, PointField::FLOAT32);

  msg.data.resize(static_cast<std::size_t>(msg.row_step));
  const bool has_ring = cloud.hasRing(), has_time = cloud.hasTime();
  std::uint8_t* out = msg.data.data();
  for (std::size_t i = 0; i < cloud.size(); ++i, out += kStep) {
    const Point& p = cloud.points[i];
    const float xyzi[4] = {p.x, p.y, p.z, p.intensity};
    const std::uint16_t ring = has_ring ? cloud.ring[i] : 0;
    const float t = has_time ? cloud.time[i] : 0.0f;
    std::memcpy(out, xyzi, sizeof(xyzi));
    std::memcpy(out + 16, &ring, sizeof(ring));
    std::memcpy(out + 18, &t, sizeof(t));
  }
  return msg;
}

ret3d::Object3D toMsg(const Box& box) {
  ret3d::Object3D m;
  m.track_id = box.track_id;
  m.label = static_cast<std::uint8_t>(box.label);
  m.score = box.score;
  m.pose.position.x = box.x;
  m.pose.position.y = box.y;
  m.pose.position.z = box.z;
  // Rotation about z by yaw: q = (cos(yaw/2), 0, 0, sin(yaw/2)).
  m.pose.orientation.w = std::cos(0.5 * box.yaw);
  m.pose.orientation.x = 0.0;
  m.pose.orientation.y = 0.0;
  m.pose.orientation.z = std::sin(0.5 * box.yaw);
  m.dimensions.x = box.length;
  m.dimensions.y = box.width;
  m.dimensions.z = box.height;
  m.velocity.x = box.vx;
  m.velocity.y = box.vy;
  m.velocity.z = 0.0;
  m.num_points = box.num_points;
  return m;
}

Box fromMsg(const ret3d::Object3D& m) {
  Box b;
  b.x = m.pose.position.x;
  b.y = m.pose.position.y;
  b.z = m.pose.position.z;
  const auto& q = m.pose.orientation;
  // Yaw of a general quaternion (z-y-x Euler convention); exact for the pure rotations about z that toMsg writes.
  b.yaw = wrapAngle(std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)));
  b.length = m.dimensions.x;
  b.width = m.dimensions.y;
  b.height = m.dimensions.z;
  b.vx = m.velocity.x;
  b.vy = m.velocity.y;
  b.score = m.score;
  b.label = m.label <= static_cast<std::uint8_t>(ObjectClass::Cyclist) ? static_cast<ObjectClass>(m.label)
                                                                       : ObjectClass::Unknown;
  b.track_id = m.track_id;
  b.num_points = m.num_points;
  return b;
}

ret3d::Object3DArray toMsg(const std::vector<Box>& boxes, const std_msgs::Header& header) {
  ret3d::Object3DArray msg;
  msg.header = header;
  msg.objects.reserve(boxes.size());
  for (const Box& b : boxes) msg.objects.push_back(toMsg(b));
  return msg;
}

std::vector<Box> fromMsg(const ret3d::Object3DArray& msg) {
  std::vector<Box> boxes;
  boxes.reserve(msg.objects.size());
  for (const auto& o : msg.objects) boxes.push_back(fromMsg(o));
  return boxes;
}

}  // namespace ret3d
