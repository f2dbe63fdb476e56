// Shared by the libFuzzer targets in test/fuzz: the fuzz input as a file for the loaders that take a path, and the
// rule every target applies to exceptions (the documented kinds are a clear refusal; anything else is a finding).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <typeinfo>

namespace ret3d {
namespace fuzz {

// A file under /tmp private to this process, removed when the object goes out of scope.
class TempFile {
 public:
  TempFile(const std::string& suffix, const std::uint8_t* data, std::size_t size)
      : path_("/tmp/ret3d_fuzz_" + std::to_string(::getpid()) + suffix) {
    std::ofstream f(path_, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  TempFile(const std::string& suffix, const std::string& bytes)
      : TempFile(suffix, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()) {}
  ~TempFile() { std::remove(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// A finding: print what was wrong and abort, so libFuzzer keeps the input as a crash.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "ret3d fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// An exception other than the documented refusals, with its type and message.
[[noreturn]] inline void unexpectedException(const char* where, const std::exception& e) {
  finding(std::string(where) + " threw " + typeid(e).name() + ": " + e.what());
}

// A documented refusal must say which file it refuses.
inline void expectNamesFile(const std::exception& e, const std::string& path) {
  if (std::string(e.what()).find(path) == std::string::npos)
    finding(std::string("error without the file name: ") + e.what());
}

}  // namespace fuzz
}  // namespace ret3d
