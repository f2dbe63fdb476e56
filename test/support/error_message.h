// The message of the error a call throws, for the tests that check what a user is told.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>

namespace ret3d {
namespace test {

// The what() of the E thrown by fn; records a failure and returns "" when fn throws nothing. An exception of another
// type passes through and fails the test.
template <typename E = std::runtime_error>
std::string errorMessage(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception, none was thrown";
  return "";
}

}  // namespace test
}  // namespace ret3d
