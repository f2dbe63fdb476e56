#include "ret3d/tracking/tracker_options.h"

#include <stdexcept>

#include "ret3d/core/yaml_reader.h"

namespace ret3d {
namespace {

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
    getOneOrPerClass(r, "output_score", &o.output_score);
    r.get("max_age", &o.max_age);
    r.get("max_time_gap", &o.max_time_gap);
    r.get("use_detection_velocity", &o.use_detection_velocity);
    r.get("velocity_window", &o.velocity_window);
    r.get("history_length", &o.history_length);
    r.finish();
    try {
      validate(o);
    } catch (const OptionError& e) {
      r.fail(e.key(), e.reason() + ", got " + e.value());
    }
  } catch (const ConfigError& e) {
    throw std::invalid_argument(e.what());
  }
  return o;
}

}  // namespace

const char* assignmentName(AssignmentMethod m) { return m == AssignmentMethod::Greedy ? "greedy" : "hungarian"; }

void validate(const TrackerOptions& o) {
  using T = TrackerOptions;
  checkOptionPerClass("gate", o.gate, T::kGate);
  checkOptionPerClass("max_speed", o.max_speed, T::kMaxSpeed);
  checkOptionPerClass("birth_score", o.birth_score, T::kScore);
  checkOptionPerClass("confirm_score", o.confirm_score, T::kScore);
  checkOptionPerClass("min_hits", o.min_hits, T::kMinHits);
  checkOptionPerClass("output_score", o.output_score, T::kScore);
  checkOption("score_threshold", o.score_threshold, T::kScore);
  checkOption("max_age", o.max_age, T::kMaxAge);
  checkOption("max_time_gap", o.max_time_gap, T::kMaxTimeGap);
  checkOption("velocity_window", o.velocity_window, T::kVelocityWindow);
  checkOption("history_length", o.history_length, T::kHistoryLength);
}

TrackerOptions parseTrackerOptions(const std::string& yaml_text) {
  return readTrackerOptions(YamlReader::parse(yaml_text, "tracker options"));
}

TrackerOptions loadTrackerOptions(const std::string& yaml_path) {
  return readTrackerOptions(YamlReader::load(yaml_path));
}

}  // namespace ret3d
