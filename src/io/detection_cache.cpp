#include "ret3d/io/detection_cache.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace ret3d {
namespace io {

namespace {

constexpr char kMagic[8] = {'R', 'E', 'T', '3', 'D', 'D', 'E', 'T'};
constexpr std::uint32_t kVersion = 1;

template <class T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

void putString(std::ostream& out, const std::string& s) {
  put<std::uint64_t>(out, s.size());
  out.write(s.data(), static_cast<std::streamsize>(s.size()));
}

class BinaryReader {
 public:
  BinaryReader(std::istream& in, const std::string& path) : in_(in), path_(path) {}
  template <class T>
  T get() {
    T v{};
    in_.read(reinterpret_cast<char*>(&v), sizeof(T));
    if (!in_) fail();
    return v;
  }
  std::string getString(std::uint64_t limit) {
    const auto n = get<std::uint64_t>();
    if (n > limit) fail();
    std::string s(n, '\0');
    in_.read(s.data(), static_cast<std::streamsize>(n));
    if (!in_) fail();
    return s;
  }
  [[noreturn]] void fail() const { throw std::runtime_error(path_ + ": truncated or corrupt detection cache"); }
  // Bytes left in the file, so counts read from it are checked before anything is allocated for them.
  std::uint64_t remaining() {
    const auto pos = in_.tellg();
    in_.seekg(0, std::ios::end);
    const auto end = in_.tellg();
    in_.seekg(pos);
    if (pos < 0 || end < pos) fail();
    return static_cast<std::uint64_t>(end - pos);
  }

 private:
  std::istream& in_;
  std::string path_;
};

}  // namespace

void writeDetectionCache(const std::string& path, const std::string& key, const SequenceDetections& detections) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error(tmp + ": cannot write the detection cache");
    out.write(kMagic, sizeof(kMagic));
    put(out, kVersion);
    putString(out, key);
    std::uint64_t entries = 0;
    for (const auto& [seq, frames] : detections) entries += frames.size();
    put(out, entries);
    for (const auto& [seq, frames] : detections) {
      for (const auto& [frame, d] : frames) {
        d.validate();
        putString(out, seq);
        put<std::int32_t>(out, frame);
        put<std::uint64_t>(out, d.boxes.size());
        put<std::uint64_t>(out, d.feature_dim);
        for (const Box& b : d.boxes) {
          for (double v : {b.x, b.y, b.z, b.length, b.width, b.height, b.yaw, b.vx, b.vy}) put(out, v);
          put(out, b.score);
          put<std::int32_t>(out, static_cast<std::int32_t>(b.label));
          put(out, b.track_id);
          put(out, b.num_points);
        }
        out.write(reinterpret_cast<const char*>(d.features.data()),
                  static_cast<std::streamsize>(d.features.size() * sizeof(float)));
      }
    }
    if (!out) throw std::runtime_error(tmp + ": writing the detection cache failed");
  }
  std::filesystem::rename(tmp, path);
}

bool readDetectionCache(const std::string& path, const std::string& key, SequenceDetections* detections) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  BinaryReader r(in, path);
  char magic[sizeof(kMagic)];
  in.read(magic, sizeof(magic));
  if (!in || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)
    throw std::runtime_error(path + ": not a ret3d detection cache");
  if (r.get<std::uint32_t>() != kVersion) return false;
  if (r.getString(1 << 20) != key) return false;
  const auto entries = r.get<std::uint64_t>();
  SequenceDetections out;
  for (std::uint64_t e = 0; e < entries; ++e) {
    const std::string seq = r.getString(1 << 10);
    const auto frame = r.get<std::int32_t>();
    const auto n = r.get<std::uint64_t>();
    const auto dim = r.get<std::uint64_t>();
    if (n > (1u << 24) || dim > (1u << 16)) r.fail();
    // A damaged count must not allocate gigabytes: the boxes and features it announces have to be in the file.
    constexpr std::uint64_t kBoxBytes = 9 * sizeof(double) + sizeof(float) + 3 * sizeof(std::uint32_t);
    if (n * (kBoxBytes + dim * sizeof(float)) > r.remaining()) r.fail();
    Detections d;
    d.feature_dim = dim;
    d.boxes.resize(n);
    for (Box& b : d.boxes) {
      for (double* v : {&b.x, &b.y, &b.z, &b.length, &b.width, &b.height, &b.yaw, &b.vx, &b.vy}) *v = r.get<double>();
      b.score = r.get<float>();
      const auto label = r.get<std::int32_t>();
      if (label < 0 || label > static_cast<std::int32_t>(ObjectClass::Cyclist)) r.fail();
      b.label = static_cast<ObjectClass>(label);
      b.track_id = r.get<std::uint32_t>();
      b.num_points = r.get<std::uint32_t>();
    }
    d.features.resize(n * dim);
    in.read(reinterpret_cast<char*>(d.features.data()), static_cast<std::streamsize>(d.features.size() * sizeof(float)));
    if (!in) r.fail();
    out[seq][frame] = std::move(d);
  }
  *detections = std::move(out);
  return true;
}

}  // namespace io
}  // namespace ret3d
