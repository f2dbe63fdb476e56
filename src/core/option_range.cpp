#include "ret3d/core/option_range.h"

#include <cmath>
#include <sstream>

namespace ret3d {

std::string optionValueText(double v) {
  // A whole number as written (10000000, not 1e+07): point limits and counts read as the user wrote them.
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string OptionRange::describe() const {
  const double inf = std::numeric_limits<double>::infinity();
  const bool no_lo = lo == -inf || lo == -kFinite, no_hi = hi == inf || hi == kFinite;
  const std::string finite = lo == -kFinite || hi == kFinite ? "a finite number " : "";
  const std::string lower = (above ? "> " : ">= ") + optionValueText(lo);
  if (no_lo && no_hi) return "must be a finite number";
  if (no_hi) return "must be " + finite + lower;
  if (no_lo) return "must be " + finite + "<= " + optionValueText(hi);
  return "must lie in " + std::string(above ? "(" : "[") + optionValueText(lo) + ", " + optionValueText(hi) + "]";
}

OptionError::OptionError(const std::string& key, const std::string& value, const std::string& reason)
    : std::invalid_argument(value.empty() ? key + ": " + reason : key + " = " + value + ": " + reason),
      key_(key),
      value_(value),
      reason_(reason) {}

OptionError OptionError::under(const std::string& prefix) const {
  return OptionError(prefix.empty() ? key_ : prefix + "." + key_, value_, reason_);
}

void checkOption(const std::string& key, double v, const OptionRange& range) {
  if (!range.contains(v)) throw OptionError(key, optionValueText(v), range.describe());
}

}  // namespace ret3d
