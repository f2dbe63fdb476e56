#include "ret3d/core/option_range.h"

#include <sstream>

namespace ret3d {

std::string optionValueText(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string OptionRange::describe() const {
  const double inf = std::numeric_limits<double>::infinity();
  if (hi == inf) return "must be >= " + optionValueText(lo);
  if (lo == -inf) return "must be <= " + optionValueText(hi);
  return "must lie in [" + optionValueText(lo) + ", " + optionValueText(hi) + "]";
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
