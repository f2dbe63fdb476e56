#include "ret3d/tracking/tracker_options.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "support/error_message.h"

namespace ret3d {
namespace {

// The message of the std::invalid_argument thrown by parsing `yaml`, or "" if none is thrown.
std::string errorOf(const std::string& yaml) {
  return test::errorOrNothing<std::invalid_argument>([&] { parseTrackerOptions(yaml); });
}

void expectSame(const TrackerOptions& a, const TrackerOptions& b) {
  EXPECT_EQ(a.assignment, b.assignment);
  for (ObjectClass c : kDetectedClasses) {
    EXPECT_DOUBLE_EQ(a.gate.at(c), b.gate.at(c)) << className(c);
    EXPECT_DOUBLE_EQ(a.max_speed.at(c), b.max_speed.at(c)) << className(c);
    EXPECT_DOUBLE_EQ(a.birth_score.at(c), b.birth_score.at(c)) << className(c);
    EXPECT_DOUBLE_EQ(a.confirm_score.at(c), b.confirm_score.at(c)) << className(c);
    EXPECT_EQ(a.min_hits.at(c), b.min_hits.at(c)) << className(c);
    EXPECT_DOUBLE_EQ(a.output_score.at(c), b.output_score.at(c)) << className(c);
  }
  EXPECT_DOUBLE_EQ(a.score_threshold, b.score_threshold);
  EXPECT_EQ(a.max_age, b.max_age);
  EXPECT_DOUBLE_EQ(a.max_time_gap, b.max_time_gap);
  EXPECT_EQ(a.use_detection_velocity, b.use_detection_velocity);
  EXPECT_EQ(a.velocity_window, b.velocity_window);
  EXPECT_EQ(a.history_length, b.history_length);
}

TEST(TrackerOptions, ConfigFileEqualsStructDefaults) {
  const TrackerOptions loaded = loadTrackerOptions(std::string(RET3D_SOURCE_DIR) + "/config/tracker.yaml");
  expectSame(loaded, TrackerOptions());
}

// The LWD-3D files start from config/tracker.yaml (`base:`) and hold what differs: these are their values in full.
TEST(TrackerOptions, TheLwd3dConfigsAreTheDefaultsWithTheirOverrides) {
  const std::string dir = std::string(RET3D_SOURCE_DIR) + "/config/";
  TrackerOptions training;  // InterRM's training data
  training.score_threshold = 0.3;
  training.birth_score = {0.5, 0.5, 0.5};
  expectSame(loadTrackerOptions(dir + "tracker_lwd3d.yaml"), training);
  TrackerOptions pipeline;  // online and offline behind the default detector
  pipeline.gate = {2.0, 0.8, 0.6};
  pipeline.score_threshold = 0.05;
  pipeline.birth_score = {0.3, 0.3, 0.45};
  pipeline.max_age = 10;
  pipeline.confirm_score = {0.4, 0.5, 0.5};  // as models/lwd3d/detector.pt publishes
  pipeline.min_hits = {3, 3, 3};
  pipeline.output_score = {0.0, 0.3, 0.0};
  expectSame(loadTrackerOptions(dir + "tracker_lwd3d_pipeline.yaml"), pipeline);
}

TEST(TrackerOptions, ReadsEveryKey) {
  const TrackerOptions o = parseTrackerOptions(
      "assignment: hungarian\n"
      "gate: {Car: 2.5, Cyclist: 0.9}\n"
      "max_speed: {Pedestrian: 4}\n"
      "score_threshold: -1\n"
      "birth_score: 2.0\n"
      "max_age: 5\n"
      "confirm_score: {Pedestrian: 0.6}\n"
      "min_hits: 3\n"
      "output_score: {Pedestrian: 0.3}\n"
      "max_time_gap: 0.5\n"
      "use_detection_velocity: false\n"
      "velocity_window: 3\n"
      "history_length: 100\n");
  EXPECT_EQ(o.assignment, AssignmentMethod::Hungarian);
  EXPECT_DOUBLE_EQ(o.gate.car, 2.5);
  EXPECT_DOUBLE_EQ(o.gate.pedestrian, TrackerOptions().gate.pedestrian);  // absent: default kept
  EXPECT_DOUBLE_EQ(o.gate.cyclist, 0.9);
  EXPECT_DOUBLE_EQ(o.max_speed.pedestrian, 4.0);
  EXPECT_DOUBLE_EQ(o.score_threshold, -1.0);
  for (ObjectClass c : kDetectedClasses) EXPECT_DOUBLE_EQ(o.birth_score.at(c), 2.0) << className(c);  // one for all
  // Or per class, absent classes keeping the default.
  const TrackerOptions per_class = parseTrackerOptions("birth_score: {Car: 0.3, Cyclist: 0.6}\n");
  EXPECT_DOUBLE_EQ(per_class.birth_score.car, 0.3);
  EXPECT_DOUBLE_EQ(per_class.birth_score.pedestrian, TrackerOptions().birth_score.pedestrian);
  EXPECT_DOUBLE_EQ(per_class.birth_score.cyclist, 0.6);
  EXPECT_EQ(o.max_age, 5);
  EXPECT_DOUBLE_EQ(o.confirm_score.pedestrian, 0.6);
  EXPECT_DOUBLE_EQ(o.confirm_score.car, TrackerOptions().confirm_score.car);
  for (ObjectClass c : kDetectedClasses) EXPECT_EQ(o.min_hits.at(c), 3) << className(c);
  EXPECT_DOUBLE_EQ(o.output_score.pedestrian, 0.3);
  EXPECT_DOUBLE_EQ(o.output_score.car, 0.0);
  EXPECT_DOUBLE_EQ(o.max_time_gap, 0.5);
  EXPECT_FALSE(o.use_detection_velocity);
  EXPECT_EQ(o.velocity_window, 3);
  EXPECT_EQ(o.history_length, 100);
  expectSame(parseTrackerOptions(""), TrackerOptions());
}

TEST(TrackerOptions, InvalidValuesNameParameterValueAndAllowed) {
  struct Case {
    const char* yaml;
    const char* name;
    const char* value;
    const char* allowed;
  };
  const Case cases[] = {
      {"assignment: optimal", "assignment", "optimal", "greedy or hungarian"},
      {"gate: {Car: -1}", "gate.Car", "-1", "> 0"},
      {"gate: {Pedestrian: 0}", "gate.Pedestrian", "0", "> 0"},
      {"gate: {Truck: 1.0}", "gate.Truck", "unknown class", "Car, Pedestrian, Cyclist"},
      {"gate: 1.0", "gate", "1.0", "a map"},
      {"max_speed: {Cyclist: -3}", "max_speed.Cyclist", "-3", ">= 0"},
      {"score_threshold: abc", "score_threshold", "abc", "a number"},
      {"birth_score: .nan", "birth_score.Car", "nan", "finite"},  // one value for all classes
      {"birth_score: {Cyclist: .nan}", "birth_score.Cyclist", "nan", "finite"},
      {"birth_score: {Truck: 0.5}", "birth_score.Truck", "unknown class", "Car, Pedestrian, Cyclist"},
      {"min_hits: 0", "min_hits.Car", "0", "[1, 1000]"},
      {"min_hits: {Pedestrian: 2.5}", "min_hits.Pedestrian", "2.5", "an integer"},
      {"confirm_score: {Cyclist: .nan}", "confirm_score.Cyclist", "nan", "finite"},
      {"output_score: {Pedestrian: .inf}", "output_score.Pedestrian", "inf", "finite"},
      {"max_age: -1", "max_age", "-1", "[0, 1000]"},
      {"max_age: 2.5", "max_age", "2.5", "an integer"},
      {"max_time_gap: 0", "max_time_gap", "0", "> 0"},
      {"use_detection_velocity: maybe", "use_detection_velocity", "maybe", "true or false"},
      {"velocity_window: 1", "velocity_window", "1", "[2, 1000]"},
      {"history_length: 0", "history_length", "0", "[1, 100000]"},
      {"histroy_length: 20", "histroy_length", "unknown key", "history_length"},  // the known keys
  };
  for (const Case& c : cases) {
    const std::string msg = errorOf(c.yaml);
    ASSERT_FALSE(msg.empty()) << "no error for: " << c.yaml;
    EXPECT_NE(msg.find(std::string("'") + c.name + "'"), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.value), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.allowed), std::string::npos) << msg;
  }
}

TEST(TrackerOptions, ValidateChecksStructsBuiltInCode) {
  TrackerOptions o;
  o.gate.cyclist = -0.5;
  try {
    validate(o);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gate.Cyclist"), std::string::npos) << e.what();
  }
}

TEST(TrackerOptions, FileErrorsNameTheFile) {
  EXPECT_THROW(loadTrackerOptions("/nonexistent/tracker.yaml"), std::runtime_error);
  try {
    loadTrackerOptions("/nonexistent/tracker.yaml");
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/tracker.yaml"), std::string::npos);
  }
  EXPECT_THROW(parseTrackerOptions("gate: [1, 2"), std::runtime_error);
}

}  // namespace
}  // namespace ret3d
