// Helpers shared by the tests.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace ret3d {
namespace test {

// The real KITTI-derived data of ../shared/data (never copied into the repository). RET3D_SHARED_DATA overrides the
// location. nullopt when absent: the calling test then skips with GTEST_SKIP() << kSharedDataMissing.
inline std::optional<std::string> sharedDataDir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("RET3D_SHARED_DATA")) {
    if (fs::is_directory(env)) return std::string(env);
    return std::nullopt;
  }
  const fs::path p = fs::path(RET3D_SOURCE_DIR) / ".." / "shared" / "data";
  if (fs::is_directory(p)) return fs::canonical(p).string();
  return std::nullopt;
}

// The six labelled KITTI object frames of ../shared/data/kitti_object/training: the project's real validation set.
// The folder may hold more frames; tests that need these check they are there.
inline const std::vector<std::string> kLabelledObjectFrames = {"000000", "000001", "000002",
                                                               "000076", "000134", "001545"};

inline constexpr const char* kSharedDataMissing =
    "../shared/data (real KITTI-derived data) is absent; set RET3D_SHARED_DATA to its location to run this test";

// A fresh empty temporary directory, removed by the destructor.
class TempDir {
 public:
  TempDir() {
    namespace fs = std::filesystem;
    std::string tmpl = (fs::temp_directory_path() / "ret3d_test_XXXXXX").string();
    char* p = mkdtemp(tmpl.data());
    path_ = p ? std::string(p) : std::string();
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// The whole file as a string ("" when it cannot be read).
inline std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace test
}  // namespace ret3d
