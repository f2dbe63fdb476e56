// The message of the kitti::ParseError a call throws: for the io tests of what a malformed KITTI file is reported as.
#pragma once

#include <functional>
#include <string>

#include "ret3d/io/kitti.h"
#include "support/error_message.h"

namespace ret3d {
namespace test {

// The what() of the ParseError thrown by fn; records a failure and returns "" when fn throws nothing.
inline std::string parseErrorMessage(const std::function<void()>& fn) { return errorMessage<kitti::ParseError>(fn); }

}  // namespace test
}  // namespace ret3d
