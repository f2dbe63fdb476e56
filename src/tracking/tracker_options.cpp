#include "ret3d/tracking/tracker_options.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ret3d/core/yaml_reader.h"

namespace ret3d {
namespace {

[[noreturn]] void invalid(const std::string& name, const std::string& value, const std::string& allowed) {
  throw std::invalid_argument("tracker option '" + name + "' = " + value + " is invalid: allowed " + allowed);
}

std::string str(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// A per-class option given as one number for every class or as a map by class.
template <typename T>
void getOneOrPerClass(YamlReader& r, const std::string& key, PerClass<T>* value) {
  T one_for_all{};
  if (r.isMap(key)) {
    r.getPerClass(key, value);
  } else if (r.get(key, &one_for_all)) {
    *value = {one_for_all, one_for_all, one_for_all};
  }
}

// Value errors are std::invalid_argument, as validate() throws them; a file that cannot be read or parsed is a
// std::runtime_error (a ConfigError).
TrackerOptions readTrackerOptions(YamlReader r) {
  TrackerOptions o;
  try {
    r.getChoice("assignment", &o.assignment,
                {{"greedy", AssignmentMethod::Greedy}, {"hungarian", AssignmentMethod::Hungarian}});
    r.getPerClass("gate", &o.gate);
    r.getPerClass("max_speed", &o.max_speed);
    r.get("score_threshold", &o.score_threshold);
    getOneOrPerClass(r, "birth_score", &o.birth_score);
    getOneOrPerClass(r, "confirm_score", &o.confirm_score);
    getOneOrPerClass(r, "min_hits", &o.min_hits);
    r.get("max_age", &o.max_age);
    r.get("max_time_gap", &o.max_time_gap);
    r.get("use_detection_velocity", &o.use_detection_velocity);
    r.get("velocity_window", &o.velocity_window);
    r.get("history_length", &o.history_length);
    r.finish();
    try {
      validate(o);
    } catch (const std::invalid_argument& e) {
      r.fail("", e.what());
    }
  } catch (const ConfigError& e) {
    throw std::invalid_argument(e.what());
  }
  return o;
}

}  // namespace

const char* assignmentName(AssignmentMethod m) { return m == AssignmentMethod::Greedy ? "greedy" : "hungarian"; }

void validate(const TrackerOptions& o) {
  for (ObjectClass c : kDetectedClasses) {
    const std::string cls = className(c);
    const double g = o.gate.at(c);
    if (!std::isfinite(g) || g <= 0.0) invalid("gate." + cls, str(g), "a finite distance > 0 (m)");
    const double s = o.max_speed.at(c);
    if (!std::isfinite(s) || s < 0.0) invalid("max_speed." + cls, str(s), "a finite speed >= 0 (m/s)");
    const double b = o.birth_score.at(c);
    if (!std::isfinite(b)) invalid("birth_score." + cls, str(b), "a finite number");
    const double cs = o.confirm_score.at(c);
    if (!std::isfinite(cs)) invalid("confirm_score." + cls, str(cs), "a finite number");
    const int h = o.min_hits.at(c);
    if (h < 1 || h > 1000) invalid("min_hits." + cls, str(h), "an integer in [1, 1000] (frames)");
  }
  if (!std::isfinite(o.score_threshold)) invalid("score_threshold", str(o.score_threshold), "a finite number");
  if (o.max_age < 0 || o.max_age > 1000) invalid("max_age", str(o.max_age), "an integer in [0, 1000] (frames)");
  if (!std::isfinite(o.max_time_gap) || o.max_time_gap <= 0.0)
    invalid("max_time_gap", str(o.max_time_gap), "a finite time > 0 (s)");
  if (o.velocity_window < 2 || o.velocity_window > 1000)
    invalid("velocity_window", str(o.velocity_window), "an integer in [2, 1000] (frames)");
  if (o.history_length < 1 || o.history_length > 100000)
    invalid("history_length", str(o.history_length), "an integer in [1, 100000] (boxes)");
}

TrackerOptions parseTrackerOptions(const std::string& yaml_text) {
  return readTrackerOptions(YamlReader::parse(yaml_text, "tracker options"));
}

TrackerOptions loadTrackerOptions(const std::string& yaml_path) {
  return readTrackerOptions(YamlReader::load(yaml_path));
}

}  // namespace ret3d
