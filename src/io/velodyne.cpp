// KITTI velodyne scans: a flat array of little-endian float32 (x, y, z, reflectance), 16 bytes per point.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "ret3d/core/log.h"
#include "ret3d/io/kitti.h"
#include "text_fields.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the velodyne reader assumes a little-endian host (KITTI .bin files are little-endian)"
#endif

namespace ret3d {
namespace kitti {

PointCloud readVelodyne(const std::string& path) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) throw std::runtime_error("cannot read '" + path + "': " + ec.message());
  if (bytes % sizeof(Point) != 0) {
    detail::fail({path, 0}, "",
                 "size " + std::to_string(bytes) + " bytes is not a multiple of 16 (4 float32 x y z reflectance per "
                 "point): not a KITTI velodyne scan, or truncated");
  }
  std::ifstream in = detail::openForRead(path);
  PointCloud cloud;
  cloud.points.resize(bytes / sizeof(Point));
  in.read(reinterpret_cast<char*>(cloud.points.data()), static_cast<std::streamsize>(bytes));
  if (static_cast<std::uint64_t>(in.gcount()) != bytes) {
    throw std::runtime_error("short read from '" + path + "'");
  }

  // Points with a non-finite coordinate carry no geometry: drop them, as the PointCloud2 conversion does.
  auto& pts = cloud.points;
  const auto end = std::remove_if(pts.begin(), pts.end(), [](const Point& p) {
    return !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z);
  });
  if (end != pts.end()) {
    RET3D_WARN(path << ": dropped " << (pts.end() - end) << " points with non-finite coordinates");
    pts.erase(end, pts.end());
  }

  // KITTI reflectance is already in [0, 1]. Files written by other tools sometimes hold 0-255 values: normalise those
  // (by 255, or by the maximum when larger) so the core always sees [0, 1].
  float max_i = 0.0f;
  for (const Point& p : pts) {
    if (std::isfinite(p.intensity)) max_i = std::max(max_i, p.intensity);
  }
  float scale = 1.0f;
  if (max_i > 1.0f) {
    scale = max_i <= 255.0f ? 1.0f / 255.0f : 1.0f / max_i;
    RET3D_WARN(path << ": reflectance up to " << max_i << " (KITTI uses [0, 1]); scaled by " << scale);
  }
  for (Point& p : pts) {
    const float i = std::isfinite(p.intensity) ? p.intensity * scale : 0.0f;
    p.intensity = std::clamp(i, 0.0f, 1.0f);
  }
  return cloud;
}

void writeVelodyne(const std::string& path, const PointCloud& cloud) {
  std::ofstream out = detail::openForWrite(path);
  out.write(reinterpret_cast<const char*>(cloud.points.data()),
            static_cast<std::streamsize>(cloud.points.size() * sizeof(Point)));
  detail::closeWritten(out, path);
}

}  // namespace kitti
}  // namespace ret3d
