// Fuzz target: sensor_msgs/PointCloud2 -> core cloud (ret3d::toCloud, src/ros/conversions.cpp).
// The input is a small layout header (fields with names, offsets and datatypes; width, height, point_step, row_step,
// endianness, is_dense, conversion options) followed by the data bytes, so every layout a driver or a broken bag
// could send is reached without deserialising. toCloud must either refuse with std::invalid_argument or return a
// cloud whose points are finite, intensities in [0, 1] and per-point arrays of the right length; an accepted cloud
// must survive toPointCloud2 -> toCloud unchanged.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "fuzz_util.h"
#include "ret3d/ros/conversions.h"

namespace {

const char* const kFieldNames[] = {"x", "y", "z", "intensity", "i", "reflectivity", "ring", "time", "t", "timestamp",
                                   "rgb"};

void checkCloud(const ret3d::PointCloud& cloud, const ret3d::CloudConversionReport& report, bool want_ring,
                bool want_time) {
  using ret3d::fuzz::finding;
  if (report.output_points != cloud.points.size()) finding("report.output_points differs from the cloud's size");
  if (report.output_points + report.dropped_nonfinite != report.input_points)
    finding("output + dropped points differ from the input points");
  for (const auto& p : cloud.points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) finding("non-finite point kept");
    if (!(p.intensity >= 0.0f && p.intensity <= 1.0f)) finding("intensity outside [0, 1]");
  }
  if (!cloud.ring.empty() && cloud.ring.size() != cloud.points.size()) finding("ring array of the wrong length");
  if (!cloud.time.empty() && cloud.time.size() != cloud.points.size()) finding("time array of the wrong length");
  for (float t : cloud.time) {
    if (!std::isfinite(t)) finding("non-finite point time");
  }
  if (report.has_ring && !want_ring) finding("ring filled although keep_ring is false");
  if (!report.time_field.empty() && !want_time) finding("time filled although keep_time is false");
}

// Reads the layout header from the front of the input (little-endian; zeros once the input runs out).
class HeaderReader {
 public:
  HeaderReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <typename T>
  T get() {
    T v{};
    const std::size_t n = std::min(sizeof(T), size_ - pos_);
    std::memcpy(&v, data_ + pos_, n);
    pos_ += n;
    return v;
  }
  std::vector<std::uint8_t> rest() const { return {data_ + pos_, data_ + size_}; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace

// Input: u8 field count (mod 9); per field u8 name (index into kFieldNames), u32 offset, u8 datatype, u8 count;
// u32 width, height, point_step, row_step; u8 flags (bit 0 big-endian, 1 dense, 2 keep_time, 3 keep_ring, bits 4-5
// intensity scaling); f64 intensity_scale; u32 stamp sec, nsec; then the data.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  HeaderReader in(data, size);
  sensor_msgs::PointCloud2 msg;
  const int n_fields = in.get<std::uint8_t>() % 9;
  for (int k = 0; k < n_fields; ++k) {
    sensor_msgs::PointField f;
    f.name = kFieldNames[in.get<std::uint8_t>() % std::size(kFieldNames)];
    f.offset = in.get<std::uint32_t>();
    f.datatype = in.get<std::uint8_t>();
    f.count = in.get<std::uint8_t>();
    msg.fields.push_back(f);
  }
  msg.width = in.get<std::uint32_t>();
  msg.height = in.get<std::uint32_t>();
  msg.point_step = in.get<std::uint32_t>();
  msg.row_step = in.get<std::uint32_t>();
  const auto flags = in.get<std::uint8_t>();
  msg.is_bigendian = flags & 1;
  msg.is_dense = (flags >> 1) & 1;
  ret3d::CloudConversionOptions options;
  options.keep_time = (flags >> 2) & 1;
  options.keep_ring = (flags >> 3) & 1;
  options.intensity_scaling = static_cast<ret3d::IntensityScaling>((flags >> 4) & 3);
  options.intensity_scale = in.get<double>();
  msg.header.stamp.sec = in.get<std::uint32_t>();
  msg.header.stamp.nsec = in.get<std::uint32_t>() % 1000000000u;
  msg.data = in.rest();

  ret3d::CloudConversionReport report;
  ret3d::PointCloud cloud;
  try {
    cloud = ret3d::toCloud(msg, options, &report);
  } catch (const std::invalid_argument&) {
    return 0;  // the documented refusal of a malformed message
  } catch (const std::exception& e) {
    ret3d::fuzz::unexpectedException("toCloud", e);
  }
  checkCloud(cloud, report, options.keep_ring, options.keep_time);

  // What the package publishes must read back as the same points.
  const sensor_msgs::PointCloud2 again = ret3d::toPointCloud2(cloud, msg.header);
  ret3d::CloudConversionOptions plain;
  plain.intensity_scaling = ret3d::IntensityScaling::DatatypeRange;
  ret3d::PointCloud back;
  try {
    back = ret3d::toCloud(again, plain);
  } catch (const std::exception& e) {
    ret3d::fuzz::unexpectedException("toCloud of toPointCloud2's output", e);
  }
  if (back.points.size() != cloud.points.size()) ret3d::fuzz::finding("round trip changed the number of points");
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const auto &a = cloud.points[i], &b = back.points[i];
    if (a.x != b.x || a.y != b.y || a.z != b.z || a.intensity != b.intensity)
      ret3d::fuzz::finding("round trip changed point " + std::to_string(i));
  }
  return 0;
}
