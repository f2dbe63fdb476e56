// Names of enum values from one table each, written in the enum's declaration order: a name is one line, and the
// static_assert beside each table (its size against the enum's last value) stops a new value without its name from
// compiling, as a switch's -Wswitch warning would have.
#pragma once

#include <array>
#include <cstddef>

namespace ret3d {

// names[e] for an enum whose values run 0, 1, ..., N - 1; `outside` for any other value (e.g. one read from a file).
template <class E, std::size_t N>
constexpr const char* enumName(E e, const std::array<const char*, N>& names, const char* outside = "?") {
  const auto i = static_cast<std::size_t>(e);
  return i < N ? names[i] : outside;
}

}  // namespace ret3d
