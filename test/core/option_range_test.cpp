// The ranges options structs keep beside their values (core/option_range.h): what each admits and how it says so,
// the one wording every reader (YAML, ROS parameters, the command line) shows.
#include "ret3d/core/option_range.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace ret3d {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kFinite = OptionRange::kFinite;

TEST(OptionRange, EachFormAdmitsWhatItSays) {
  const OptionRange closed{0, 1}, positive{0, kFinite, true}, finite{-kFinite, kFinite}, at_least{1, kInf};
  EXPECT_TRUE(closed.contains(0) && closed.contains(1));
  EXPECT_FALSE(closed.contains(1.5) || closed.contains(std::nan("")));
  EXPECT_FALSE(positive.contains(0));
  EXPECT_TRUE(positive.contains(1e-9));
  EXPECT_FALSE(positive.contains(kInf));
  EXPECT_TRUE(finite.contains(-1e300) && finite.contains(0));
  EXPECT_FALSE(finite.contains(kInf) || finite.contains(-kInf) || finite.contains(std::nan("")));
  EXPECT_TRUE(at_least.contains(kInf));  // unbounded above: infinity admitted
}

TEST(OptionRange, EachFormDescribesItself) {
  EXPECT_EQ((OptionRange{0, 1}).describe(), "must lie in [0, 1]");
  EXPECT_EQ((OptionRange{0, 1, true}).describe(), "must lie in (0, 1]");
  EXPECT_EQ((OptionRange{1, kInf}).describe(), "must be >= 1");
  EXPECT_EQ((OptionRange{-kInf, 5}).describe(), "must be <= 5");
  EXPECT_EQ((OptionRange{0, kFinite, true}).describe(), "must be a finite number > 0");
  EXPECT_EQ((OptionRange{0, kFinite}).describe(), "must be a finite number >= 0");
  EXPECT_EQ((OptionRange{-kFinite, kFinite}).describe(), "must be a finite number");
  EXPECT_EQ((OptionRange{1000, 10000000}).describe(), "must lie in [1000, 10000000]");  // whole numbers as written
  EXPECT_EQ(optionValueText(1e-6), "1e-06");
  EXPECT_EQ(optionValueText(-0.5), "-0.5");
}

TEST(OptionRange, CheckOptionNamesKeyValueAndRange) {
  try {
    checkOption("gate.Car", -1, OptionRange{0, kFinite, true});
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(std::string(e.what()), "gate.Car = -1: must be a finite number > 0");
    EXPECT_EQ(e.under("tracker").key(), "tracker.gate.Car");
  }
}

}  // namespace
}  // namespace ret3d
