// The allowed range of a numeric option, kept beside its options struct so that every way in (YAML, ROS parameters,
// dynamic_reconfigure, the command line) checks the same range and says it in the same words; and the error an
// options struct's validate() throws, naming the key, the value and what is allowed.
#pragma once

#include <limits>
#include <stdexcept>
#include <string>

#include "ret3d/core/types.h"

namespace ret3d {

struct OptionRange {
  // A bound of +-kFinite (the largest double) is no bound but finiteness: infinities are outside.
  static constexpr double kFinite = std::numeric_limits<double>::max();
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool above = false;  // true: lo itself is outside (v > lo), e.g. a distance that must be positive

  bool contains(double v) const { return (above ? v > lo : v >= lo) && v <= hi; }  // false for NaN
  // "must lie in [0, 1]", "must be >= 1", "must be <= 5", "must be a finite number > 0", "must be a finite number".
  std::string describe() const;
};

// what(): "KEY = VALUE: REASON", e.g. "nms_iou = 1.5: must lie in [0, 1]" ("KEY: REASON" without a value, for a
// part checked as a whole). The key is the option's YAML key below
// its struct (e.g. "nms_iou", "grid_extent"), which each reader turns into its own name for it.
class OptionError : public std::invalid_argument {
 public:
  OptionError(const std::string& key, const std::string& value, const std::string& reason);
  const std::string& key() const { return key_; }
  const std::string& value() const { return value_; }
  const std::string& reason() const { return reason_; }
  // The same error for the key under `prefix` (e.g. "inference" + "nms_iou").
  OptionError under(const std::string& prefix) const;

 private:
  std::string key_, value_, reason_;
};

// A number as messages show it (shortest form: 0.1, 1e-06).
std::string optionValueText(double v);

// Throws OptionError(key, v, range.describe()) unless range.contains(v).
void checkOption(const std::string& key, double v, const OptionRange& range);

// checkOption for a per-class value of each detected class, keyed "key.Car", "key.Pedestrian", ...
template <class PerClassValues>
void checkOptionPerClass(const std::string& key, const PerClassValues& values, const OptionRange& range) {
  for (ObjectClass c : kDetectedClasses) checkOption(key + "." + className(c), values.at(c), range);
}

}  // namespace ret3d
