// The message of the error a call throws, for the tests that check what a user is told.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

namespace ret3d {
namespace test {

// The what() of the E thrown by fn; nullopt when fn throws nothing. An exception of another type passes through and
// fails the test.
template <typename E = std::runtime_error>
std::optional<std::string> thrownMessage(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const E& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

// The what() of the E thrown by fn; records a failure and returns "" when fn throws nothing.
template <typename E = std::runtime_error>
std::string errorMessage(const std::function<void()>& fn) {
  const auto message = thrownMessage<E>(fn);
  if (!message) ADD_FAILURE() << "expected an exception, none was thrown";
  return message.value_or("");
}

// The what() of the E thrown by fn, or "" when fn throws nothing (for tests of refusals and acceptances alike).
template <typename E = std::runtime_error>
std::string errorOrNothing(const std::function<void()>& fn) {
  return thrownMessage<E>(fn).value_or("");
}

}  // namespace test
}  // namespace ret3d
