// Shared by the io tests: the message of the kitti::ParseError a call throws.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "ret3d/io/kitti.h"

namespace ret3d {
namespace test {

// The what() of the ParseError thrown by fn; records a failure and returns "" when fn throws nothing.
inline std::string parseErrorMessage(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const kitti::ParseError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected kitti::ParseError";
  return "";
}

}  // namespace test
}  // namespace ret3d
