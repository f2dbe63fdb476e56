#include "ret3d/tracking/tracker_options.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

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

// The scalar text of a node, for error messages.
std::string text(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  std::ostringstream os;
  os << YAML::Dump(n);
  return os.str();
}

// The scalar as T, or an error naming the parameter and what it must be.
template <typename T>
T read(const YAML::Node& n, const std::string& name, const char* what) {
  if (!n.IsScalar()) invalid(name, text(n), what);
  try {
    return n.as<T>();
  } catch (const YAML::Exception&) {
    invalid(name, text(n), what);
  }
}
double readDouble(const YAML::Node& n, const std::string& name) { return read<double>(n, name, "a number"); }
int readInt(const YAML::Node& n, const std::string& name) { return read<int>(n, name, "an integer"); }
bool readBool(const YAML::Node& n, const std::string& name) { return read<bool>(n, name, "true or false"); }

void readPerClass(const YAML::Node& n, const std::string& name, PerClass<double>& out) {
  if (!n.IsMap()) invalid(name, text(n), "a map with keys Car, Pedestrian, Cyclist");
  for (const auto& kv : n) {
    const std::string key = kv.first.as<std::string>();
    const std::optional<ObjectClass> c = classFromName(key);
    if (!c) invalid(name + "." + key, text(kv.second), "class keys Car, Pedestrian, Cyclist only");
    out.at(*c) = readDouble(kv.second, name + "." + key);
  }
}

TrackerOptions fromNode(const YAML::Node& root) {
  TrackerOptions o;
  if (!root || root.IsNull()) return o;
  if (!root.IsMap()) invalid("(document)", text(root), "a map of tracker options");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    if (key == "assignment") {
      const std::string s = v.IsScalar() ? v.Scalar() : std::string();
      if (s == "greedy") {
        o.assignment = AssignmentMethod::Greedy;
      } else if (s == "hungarian") {
        o.assignment = AssignmentMethod::Hungarian;
      } else {
        invalid(key, text(v), "greedy or hungarian");
      }
    } else if (key == "gate") {
      readPerClass(v, key, o.gate);
    } else if (key == "max_speed") {
      readPerClass(v, key, o.max_speed);
    } else if (key == "score_threshold") {
      o.score_threshold = readDouble(v, key);
    } else if (key == "birth_score") {
      if (v.IsScalar()) {
        const double b = readDouble(v, key);
        o.birth_score = {b, b, b};
      } else {
        readPerClass(v, key, o.birth_score);
      }
    } else if (key == "max_age") {
      o.max_age = readInt(v, key);
    } else if (key == "max_time_gap") {
      o.max_time_gap = readDouble(v, key);
    } else if (key == "use_detection_velocity") {
      o.use_detection_velocity = readBool(v, key);
    } else if (key == "velocity_window") {
      o.velocity_window = readInt(v, key);
    } else if (key == "history_length") {
      o.history_length = readInt(v, key);
    } else {
      invalid(key, text(v),
              "keys assignment, gate, max_speed, score_threshold, birth_score, max_age, max_time_gap, "
              "use_detection_velocity, velocity_window, history_length (unknown key)");
    }
  }
  validate(o);
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
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("tracker options: YAML parse error: ") + e.what());
  }
  try {
    return fromNode(root);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("tracker options: ") + e.what());
  }
}

TrackerOptions loadTrackerOptions(const std::string& yaml_path) {
  std::ifstream in(yaml_path);
  if (!in) throw std::runtime_error("tracker options: cannot read " + yaml_path);
  YAML::Node root;
  try {
    root = YAML::Load(in);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(yaml_path + ": YAML parse error: " + e.what());
  }
  try {
    return fromNode(root);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(yaml_path + ": " + e.what());
  } catch (const YAML::Exception& e) {  // a value of the wrong type, e.g. a list where a name belongs
    throw std::runtime_error(yaml_path + ": " + e.what());
  }
}

}  // namespace ret3d
