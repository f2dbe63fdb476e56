#include "ret3d/ros/conversions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>

#include "support/boxes.h"

namespace ret3d {
namespace {

using sensor_msgs::PointField;

struct FieldSpec {
  std::string name;
  std::uint32_t offset;
  std::uint8_t datatype;
};

// x, y, z float32 at offsets 0, 4, 8, then `extra`.
std::vector<FieldSpec> xyzAnd(const std::vector<FieldSpec>& extra) {
  std::vector<FieldSpec> fields = {
      {"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}, {"z", 8, PointField::FLOAT32}};
  fields.insert(fields.end(), extra.begin(), extra.end());
  return fields;
}

// The velodyne driver's packed 22-byte layout.
std::vector<FieldSpec> velodyneFields() {
  return xyzAnd(
      {{"intensity", 12, PointField::FLOAT32}, {"ring", 16, PointField::UINT16}, {"time", 18, PointField::FLOAT32}});
}

template <typename T>
void storeAs(double v, std::uint8_t* out, bool swap) {
  const T t = static_cast<T>(v);
  std::uint8_t b[sizeof(T)];
  std::memcpy(b, &t, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  std::memcpy(out, b, sizeof(T));
}

void store(std::uint8_t datatype, double v, std::uint8_t* out, bool swap) {
  using Store = void (*)(double, std::uint8_t*, bool);
  static const std::map<std::uint8_t, Store> kStores = {
      {PointField::INT8, storeAs<std::int8_t>},   {PointField::UINT8, storeAs<std::uint8_t>},
      {PointField::INT16, storeAs<std::int16_t>}, {PointField::UINT16, storeAs<std::uint16_t>},
      {PointField::INT32, storeAs<std::int32_t>}, {PointField::UINT32, storeAs<std::uint32_t>},
      {PointField::FLOAT32, storeAs<float>},      {PointField::FLOAT64, storeAs<double>}};
  const auto it = kStores.find(datatype);
  ASSERT_NE(it, kStores.end()) << "bad datatype " << static_cast<int>(datatype);
  it->second(v, out, swap);
}

// A PointCloud2 written byte by byte from per-point field values, independently of the code under test. Padding
// bytes are filled with 0xAB so a reader that strays into them produces garbage. `big_endian` writes every value
// byte-swapped (the test host is little-endian) and sets is_bigendian.
sensor_msgs::PointCloud2 buildCloud(const std::vector<FieldSpec>& fields, std::uint32_t point_step,
                                    const std::vector<std::map<std::string, double>>& points, std::uint32_t width,
                                    std::uint32_t height, std::uint32_t row_step, bool big_endian = false) {
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = "sensor";
  msg.header.stamp.fromSec(100.0);
  msg.width = width;
  msg.height = height;
  msg.point_step = point_step;
  msg.row_step = row_step;
  msg.is_bigendian = big_endian;
  msg.is_dense = false;
  for (const auto& f : fields) {
    PointField pf;
    pf.name = f.name;
    pf.offset = f.offset;
    pf.datatype = f.datatype;
    pf.count = 1;
    msg.fields.push_back(pf);
  }
  msg.data.assign(static_cast<std::size_t>(row_step) * height, 0xAB);
  for (std::uint32_t r = 0; r < height; ++r) {
    for (std::uint32_t c = 0; c < width; ++c) {
      const auto& values = points.at(r * width + c);
      std::uint8_t* p = msg.data.data() + r * row_step + c * point_step;
      for (const auto& f : fields) store(f.datatype, values.at(f.name), p + f.offset, big_endian);
    }
  }
  return msg;
}

sensor_msgs::PointCloud2 buildCloud(const std::vector<FieldSpec>& fields, std::uint32_t point_step,
                                    const std::vector<std::map<std::string, double>>& points, bool big_endian = false) {
  const auto n = static_cast<std::uint32_t>(points.size());
  return buildCloud(fields, point_step, points, n, 1, n * point_step, big_endian);
}

std::vector<std::map<std::string, double>> randomPoints(std::size_t n, double intensity_max, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-60.0, 60.0), z(-3.0, 2.0), unit(0.0, 1.0);
  std::vector<std::map<std::string, double>> pts;
  for (std::size_t i = 0; i < n; ++i) {
    // Positions on a 1 cm grid so float32 storage is exact enough to compare at 1e-4.
    pts.push_back({{"x", std::round(pos(rng) * 100) / 100},
                   {"y", std::round(pos(rng) * 100) / 100},
                   {"z", std::round(z(rng) * 100) / 100},
                   {"intensity", std::round(unit(rng) * intensity_max)},
                   {"ring", static_cast<double>(i % 64)},
                   {"time", 0.1 * static_cast<double>(i) / static_cast<double>(n)}});
  }
  // The largest intensity is reached, so observed-max normalisation divides by intensity_max exactly.
  if (!pts.empty()) pts.front()["intensity"] = intensity_max;
  return pts;
}

void expectSamePoints(const PointCloud& cloud, const std::vector<std::map<std::string, double>>& pts) {
  ASSERT_EQ(cloud.size(), pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(cloud.points[i].x, pts[i].at("x"), 1e-4) << i;
    EXPECT_NEAR(cloud.points[i].y, pts[i].at("y"), 1e-4) << i;
    EXPECT_NEAR(cloud.points[i].z, pts[i].at("z"), 1e-4) << i;
  }
}

void expectIntensityInUnitRange(const PointCloud& cloud) {
  for (const auto& p : cloud.points) {
    ASSERT_GE(p.intensity, 0.0f);
    ASSERT_LE(p.intensity, 1.0f);
  }
}

TEST(ToCloud, VelodyneLayoutPacked22BytesFloatIntensity0To255) {
  const auto fields = velodyneFields();
  const auto pts = randomPoints(500, 255.0);
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 22, pts), {}, &report);
  expectSamePoints(cloud, pts);
  expectIntensityInUnitRange(cloud);
  EXPECT_EQ(report.intensity_field, "intensity");
  EXPECT_DOUBLE_EQ(report.intensity_divisor, 255.0);
  ASSERT_TRUE(cloud.hasRing());
  ASSERT_TRUE(cloud.hasTime());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(cloud.points[i].intensity, pts[i].at("intensity") / 255.0, 1e-6);
    EXPECT_EQ(cloud.ring[i], static_cast<std::uint16_t>(pts[i].at("ring")));
    EXPECT_NEAR(cloud.time[i], pts[i].at("time"), 1e-7);
  }
  EXPECT_TRUE(report.warnings.empty());
}

TEST(ToCloud, OusterLayout48BytesWithPaddingReflectivityAndNanosecondTime) {
  // ouster_ros' PointXYZIRCAEDT-era layout: x y z, 4 bytes padding, intensity float32, t uint32 (ns), reflectivity
  // uint16, ring uint16, ambient uint16, range uint32, then padding to 48 bytes.
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT32},    {"y", 4, PointField::FLOAT32},
                                         {"z", 8, PointField::FLOAT32},    {"intensity", 16, PointField::FLOAT32},
                                         {"t", 20, PointField::UINT32},    {"reflectivity", 24, PointField::UINT16},
                                         {"ring", 26, PointField::UINT16}, {"ambient", 28, PointField::UINT16},
                                         {"range", 32, PointField::UINT32}};
  auto pts = randomPoints(400, 3000.0, 7);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i]["t"] = 25000.0 * static_cast<double>(i);  // ns
    pts[i]["reflectivity"] = static_cast<double>(i % 1000);
    pts[i]["ambient"] = 7;
    pts[i]["range"] = 12345;
  }
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 48, pts), {}, &report);
  expectSamePoints(cloud, pts);
  expectIntensityInUnitRange(cloud);
  EXPECT_EQ(report.intensity_field, "intensity");  // preferred over reflectivity
  EXPECT_EQ(report.time_field, "t");
  ASSERT_TRUE(cloud.hasTime());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(cloud.points[i].intensity, pts[i].at("intensity") / 3000.0, 1e-6);
    EXPECT_NEAR(cloud.time[i], pts[i].at("t") * 1e-9, 1e-9);
    EXPECT_EQ(cloud.ring[i], static_cast<std::uint16_t>(pts[i].at("ring")));
  }
}

TEST(ToCloud, ReflectivityUsedWhenNoIntensityField) {
  const auto fields = xyzAnd({{"reflectivity", 12, PointField::UINT16}});
  auto pts = randomPoints(50, 1.0);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i]["reflectivity"] = 1000.0 * static_cast<double>(i);
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 16, pts), {}, &report);
  EXPECT_EQ(report.intensity_field, "reflectivity");
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(cloud.points[i].intensity, 1000.0 * static_cast<double>(i) / 65535.0, 1e-6);
  }
}

TEST(ToCloud, PlainXYZIFloat32KeepsUnitIntensityAsIs) {
  const auto fields = xyzAnd({{"intensity", 12, PointField::FLOAT32}});
  auto pts = randomPoints(300, 100.0, 3);
  for (auto& p : pts) p["intensity"] /= 100.0;  // KITTI reflectance in [0, 1]
  pts.front()["intensity"] = 0.83;              // observed max below 1: values kept as they are
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 16, pts), {}, &report);
  expectSamePoints(cloud, pts);
  EXPECT_FALSE(cloud.hasRing());
  EXPECT_FALSE(cloud.hasTime());
  EXPECT_DOUBLE_EQ(report.intensity_divisor, 1.0);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_NEAR(cloud.points[i].intensity, pts[i].at("intensity"), 1e-6);
}

TEST(ToCloud, ShortIntensityFieldNameI) {
  const auto fields = xyzAnd({{"i", 12, PointField::FLOAT32}});
  auto pts = randomPoints(20, 1.0);
  for (auto& p : pts) p["i"] = 0.5;
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 16, pts), {}, &report);
  EXPECT_EQ(report.intensity_field, "i");
  for (const auto& p : cloud.points) EXPECT_FLOAT_EQ(p.intensity, 0.5f);
}

TEST(ToCloud, Uint8IntensityDividedBy255) {
  const auto fields = xyzAnd({{"intensity", 12, PointField::UINT8}});
  auto pts = randomPoints(256, 1.0);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i]["intensity"] = static_cast<double>(i);
  const PointCloud cloud = toCloud(buildCloud(fields, 13, pts));  // odd point_step, unaligned floats
  expectSamePoints(cloud, pts);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(cloud.points[i].intensity, static_cast<double>(i) / 255.0, 1e-6);
  }
  EXPECT_FLOAT_EQ(cloud.points.back().intensity, 1.0f);
}

TEST(ToCloud, NoIntensityGivesZerosAndOneWarning) {
  const auto fields = xyzAnd({});
  const auto pts = randomPoints(40, 1.0);
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 12, pts), {}, &report);
  expectSamePoints(cloud, pts);
  for (const auto& p : cloud.points) EXPECT_EQ(p.intensity, 0.0f);
  EXPECT_TRUE(report.intensity_field.empty());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("intensity"), std::string::npos);
}

TEST(ToCloud, NonFinitePointsDroppedAndCounted) {
  const auto fields = velodyneFields();
  auto pts = randomPoints(100, 255.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  pts[3]["x"] = nan;
  pts[10]["y"] = inf;
  pts[11]["z"] = -inf;
  pts[50]["x"] = nan;
  pts[50]["y"] = nan;
  pts[50]["z"] = nan;
  pts[60]["intensity"] = nan;  // a valid point with a bad intensity stays, with intensity 0
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 22, pts), {}, &report);
  EXPECT_EQ(report.input_points, 100u);
  EXPECT_EQ(report.dropped_nonfinite, 4u);
  EXPECT_EQ(report.output_points, 96u);
  std::vector<std::map<std::string, double>> kept;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i != 3 && i != 10 && i != 11 && i != 50) kept.push_back(pts[i]);
  }
  expectSamePoints(cloud, kept);
  ASSERT_EQ(cloud.ring.size(), 96u);
  ASSERT_EQ(cloud.time.size(), 96u);
  EXPECT_EQ(cloud.ring[3], static_cast<std::uint16_t>(pts[4].at("ring")));  // extras stay aligned with points
  expectIntensityInUnitRange(cloud);
  EXPECT_EQ(cloud.points[56].intensity, 0.0f);  // pts[60] after 4 drops
}

// Found by fuzzing (test/fuzz/regressions/pointcloud2): float64 values beyond float's range became infinite points
// (and infinite times) in the core cloud; a tiny FixedScale divisor gave NaN intensities.
TEST(ToCloud, Float64BeyondFloatRangeIsDroppedLikeNonFinite) {
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT64},
                                         {"y", 8, PointField::FLOAT64},
                                         {"z", 16, PointField::FLOAT64},
                                         {"intensity", 24, PointField::FLOAT64},
                                         {"time", 32, PointField::FLOAT64}};
  auto pts = randomPoints(4, 255.0);
  pts[1]["x"] = 1e300;
  pts[2]["intensity"] = -1e300;
  pts[3]["time"] = 1e300;
  CloudConversionReport report;
  const PointCloud cloud = toCloud(buildCloud(fields, 40, pts), {}, &report);
  EXPECT_EQ(report.dropped_nonfinite, 1u);
  ASSERT_EQ(cloud.size(), 3u);
  expectIntensityInUnitRange(cloud);
  EXPECT_EQ(cloud.points[1].intensity, 0.0f);  // pts[2]: kept, its unusable intensity 0
  for (float t : cloud.time) EXPECT_TRUE(std::isfinite(t)) << t;
}

TEST(ToCloud, TinyFixedScaleGivesIntensitiesInUnitRange) {
  const auto fields = xyzAnd({{"intensity", 12, PointField::UINT16}});
  auto pts = randomPoints(3, 1.0);
  pts[0]["intensity"] = 0;
  pts[1]["intensity"] = 7;
  CloudConversionOptions opt;
  opt.intensity_scaling = IntensityScaling::FixedScale;
  opt.intensity_scale = 1e-310;  // 1 / scale overflows
  const PointCloud cloud = toCloud(buildCloud(fields, 16, pts), opt);
  expectIntensityInUnitRange(cloud);
  EXPECT_EQ(cloud.points[0].intensity, 0.0f);
  EXPECT_EQ(cloud.points[1].intensity, 1.0f);
}

TEST(ToCloud, BigEndianIsByteSwapped) {
  const auto fields = xyzAnd(
      {{"intensity", 12, PointField::UINT16}, {"ring", 14, PointField::UINT16}, {"time", 16, PointField::FLOAT64}});
  auto pts = randomPoints(100, 60000.0);
  const PointCloud big = toCloud(buildCloud(fields, 24, pts, /*big_endian=*/true));
  const PointCloud little = toCloud(buildCloud(fields, 24, pts, /*big_endian=*/false));
  expectSamePoints(big, pts);
  expectIntensityInUnitRange(big);
  ASSERT_EQ(big.size(), little.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(big.points[i].intensity, pts[i].at("intensity") / 65535.0, 1e-6);
    EXPECT_EQ(big.points[i].intensity, little.points[i].intensity);
    EXPECT_EQ(big.ring[i], static_cast<std::uint16_t>(pts[i].at("ring")));
    EXPECT_NEAR(big.time[i], pts[i].at("time"), 1e-7);
  }
}

TEST(ToCloud, EmptyCloud) {
  const auto fields = xyzAnd({{"intensity", 12, PointField::FLOAT32}});
  CloudConversionReport report;
  EXPECT_TRUE(toCloud(buildCloud(fields, 16, {}), {}, &report).empty());
  EXPECT_EQ(report.input_points, 0u);
  // A default-constructed message (no fields, no data) is an empty scan too, not an error.
  EXPECT_TRUE(toCloud(sensor_msgs::PointCloud2()).empty());
}

TEST(ToCloud, OrganizedCloudWithRowPadding) {
  const auto fields = xyzAnd({{"intensity", 16, PointField::FLOAT32}});
  constexpr std::uint32_t kWidth = 16, kHeight = 8, kStep = 32, kRowStep = kWidth * kStep + 24;  // 24 bytes row pad
  auto pts = randomPoints(kWidth * kHeight, 200.0, 11);
  pts[5]["x"] = std::numeric_limits<double>::quiet_NaN();  // organized clouds mark missing returns with NaN
  const PointCloud cloud = toCloud(buildCloud(fields, kStep, pts, kWidth, kHeight, kRowStep));
  pts.erase(pts.begin() + 5);
  expectSamePoints(cloud, pts);  // row-major order
  expectIntensityInUnitRange(cloud);
}

TEST(ToCloud, OverMaxPointsAnEvenSelectionOfExactlyThatManyIsKept) {
  // Organized 8 x 125 = 1000 points, x = the point's row-major index; a limit of 300.
  const auto fields = xyzAnd({{"intensity", 12, PointField::FLOAT32}});
  constexpr std::uint32_t kWidth = 125, kHeight = 8;
  auto pts = randomPoints(kWidth * kHeight, 1.0, 3);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i]["x"] = static_cast<double>(i);
  const sensor_msgs::PointCloud2 msg = buildCloud(fields, 16, pts, kWidth, kHeight, kWidth * 16);
  CloudConversionOptions options;
  options.max_points = 300;
  CloudConversionReport report;
  const PointCloud cloud = toCloud(msg, options, &report);
  EXPECT_TRUE(report.thinned);
  EXPECT_EQ(report.input_points, 1000u);
  ASSERT_EQ(cloud.size(), 300u);
  EXPECT_EQ(report.output_points, 300u);
  // Evenly spread over every row: gaps of 3 or 4 indices, the whole index range covered.
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    const float gap = cloud.points[i].x - cloud.points[i - 1].x;
    EXPECT_TRUE(gap == 3.0f || gap == 4.0f) << "at " << i << ": " << gap;
  }
  EXPECT_LE(cloud.points.front().x, 3.0f);
  EXPECT_GE(cloud.points.back().x, 996.0f);
  // The same points every time; at or under the limit nothing is thinned.
  const PointCloud again = toCloud(msg, options);
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(again.points[i].x, cloud.points[i].x);
  options.max_points = 1000;
  EXPECT_EQ(toCloud(msg, options, &report).size(), 1000u);
  EXPECT_FALSE(report.thinned);
}

TEST(ToCloud, Float64AndIntegerCoordinates) {
  const std::vector<FieldSpec> fields = {{"x", 0, PointField::FLOAT64},
                                         {"y", 8, PointField::FLOAT64},
                                         {"z", 16, PointField::FLOAT64},
                                         {"intensity", 24, PointField::FLOAT64}};
  const auto pts = randomPoints(100, 255.0, 5);
  const PointCloud cloud = toCloud(buildCloud(fields, 32, pts));
  expectSamePoints(cloud, pts);
  expectIntensityInUnitRange(cloud);

  // Integer coordinates (e.g. a depth-camera style int16 cloud) are read as their values.
  const std::vector<FieldSpec> int_fields = {{"x", 0, PointField::INT16},
                                             {"y", 2, PointField::INT16},
                                             {"z", 4, PointField::INT8},
                                             {"intensity", 5, PointField::INT8}};
  std::vector<std::map<std::string, double>> ipts = {{{"x", -5}, {"y", 300}, {"z", -2}, {"intensity", 127}},
                                                     {{"x", 7}, {"y", -1}, {"z", 3}, {"intensity", -4}}};
  const PointCloud icloud = toCloud(buildCloud(int_fields, 6, ipts));
  expectSamePoints(icloud, ipts);
  EXPECT_FLOAT_EQ(icloud.points[0].intensity, 1.0f);  // int8 127 / 127
  EXPECT_FLOAT_EQ(icloud.points[1].intensity, 0.0f);  // negatives clamp to 0
}

TEST(ToCloud, IntensityScalingRules) {
  const auto fields = xyzAnd({{"intensity", 12, PointField::UINT16}});
  auto pts = randomPoints(3, 1.0);
  pts[0]["intensity"] = 100;
  pts[1]["intensity"] = 400;
  pts[2]["intensity"] = 1000;
  const auto msg = buildCloud(fields, 16, pts);

  CloudConversionOptions opt;
  opt.intensity_scaling = IntensityScaling::DatatypeRange;
  EXPECT_NEAR(toCloud(msg, opt).points[2].intensity, 1000.0 / 65535.0, 1e-7);
  opt.intensity_scaling = IntensityScaling::ObservedMax;
  EXPECT_NEAR(toCloud(msg, opt).points[1].intensity, 0.4, 1e-6);
  opt.intensity_scaling = IntensityScaling::FixedScale;
  opt.intensity_scale = 500.0;
  const PointCloud fixed = toCloud(msg, opt);
  EXPECT_NEAR(fixed.points[0].intensity, 0.2, 1e-6);
  EXPECT_NEAR(fixed.points[1].intensity, 0.8, 1e-6);
  EXPECT_FLOAT_EQ(fixed.points[2].intensity, 1.0f);  // clamped
  opt.intensity_scale = 0.0;
  EXPECT_THROW(toCloud(msg, opt), std::invalid_argument);
}

TEST(ToCloud, AbsoluteFloat64TimestampsBecomeOffsetsFromTheHeaderStamp) {
  const auto fields = xyzAnd({{"timestamp", 16, PointField::FLOAT64}});
  auto pts = randomPoints(10, 1.0);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i]["timestamp"] = 1700000000.0 + 0.01 * static_cast<double>(i);
  auto msg = buildCloud(fields, 24, pts);
  msg.header.stamp.fromSec(1700000000.0);
  CloudConversionReport report;
  const PointCloud cloud = toCloud(msg, {}, &report);
  EXPECT_EQ(report.time_field, "timestamp");
  ASSERT_TRUE(cloud.hasTime());
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_NEAR(cloud.time[i], 0.01 * static_cast<double>(i), 1e-5);
}

TEST(ToCloud, MalformedMessagesThrowClearErrors) {
  const auto fields = xyzAnd({{"intensity", 12, PointField::FLOAT32}});
  const auto pts = randomPoints(10, 1.0);
  const auto good = buildCloud(fields, 16, pts);

  auto expectThrowMentioning = [](const sensor_msgs::PointCloud2& msg, const std::string& what) {
    try {
      toCloud(msg);
      ADD_FAILURE() << "no exception; expected one mentioning '" << what << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };

  auto short_data = good;
  short_data.data.resize(good.data.size() - 1);
  expectThrowMentioning(short_data, "bytes");

  auto no_z = good;
  no_z.fields.erase(no_z.fields.begin() + 2);
  expectThrowMentioning(no_z, "'z'");

  auto past_step = good;
  past_step.fields[3].offset = 14;  // float32 at 14..17 in a 16-byte point
  expectThrowMentioning(past_step, "past point_step");

  auto bad_type = good;
  bad_type.fields[0].datatype = 42;
  expectThrowMentioning(bad_type, "datatype");

  auto bad_row_step = good;
  bad_row_step.row_step = 10;
  expectThrowMentioning(bad_row_step, "row_step");
}

TEST(ToPointCloud2, VelodyneDriverLayoutAndRoundTrip) {
  PointCloud cloud;
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> pos(-50.f, 50.f), unit(0.f, 1.f);
  for (int i = 0; i < 1000; ++i) {
    cloud.push_back({pos(rng), pos(rng), pos(rng), unit(rng)}, 0.1f * unit(rng), static_cast<std::uint16_t>(i % 64),
                    true);
  }
  std_msgs::Header header;
  header.frame_id = "velodyne";
  header.stamp.fromSec(1234.5);
  const sensor_msgs::PointCloud2 msg = toPointCloud2(cloud, header);
  EXPECT_EQ(msg.header.frame_id, "velodyne");
  EXPECT_EQ(msg.header.stamp, header.stamp);
  EXPECT_EQ(msg.point_step, 22u);
  EXPECT_EQ(msg.height, 1u);
  EXPECT_EQ(msg.width, 1000u);
  EXPECT_EQ(msg.row_step, 22000u);
  EXPECT_EQ(msg.data.size(), 22000u);
  const std::vector<std::tuple<std::string, std::uint32_t, std::uint8_t>> expected = {
      {"x", 0, PointField::FLOAT32},          {"y", 4, PointField::FLOAT32},    {"z", 8, PointField::FLOAT32},
      {"intensity", 12, PointField::FLOAT32}, {"ring", 16, PointField::UINT16}, {"time", 18, PointField::FLOAT32}};
  ASSERT_EQ(msg.fields.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(msg.fields[i].name, std::get<0>(expected[i]));
    EXPECT_EQ(msg.fields[i].offset, std::get<1>(expected[i]));
    EXPECT_EQ(msg.fields[i].datatype, std::get<2>(expected[i]));
    EXPECT_EQ(msg.fields[i].count, 1u);
  }

  const PointCloud back = toCloud(msg);
  ASSERT_EQ(back.size(), cloud.size());
  ASSERT_TRUE(back.hasRing());
  ASSERT_TRUE(back.hasTime());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_EQ(back.points[i].x, cloud.points[i].x);
    EXPECT_EQ(back.points[i].y, cloud.points[i].y);
    EXPECT_EQ(back.points[i].z, cloud.points[i].z);
    EXPECT_EQ(back.points[i].intensity, cloud.points[i].intensity);
    EXPECT_EQ(back.ring[i], cloud.ring[i]);
    EXPECT_EQ(back.time[i], cloud.time[i]);
  }

  // A cloud without ring and time gets zeros there; empty clouds convert both ways.
  PointCloud plain;
  plain.points.push_back({1, 2, 3, 0.5f});
  const PointCloud plain_back = toCloud(toPointCloud2(plain, header));
  ASSERT_EQ(plain_back.size(), 1u);
  EXPECT_EQ(plain_back.ring[0], 0);
  EXPECT_EQ(plain_back.time[0], 0.0f);
  EXPECT_TRUE(toCloud(toPointCloud2(PointCloud(), header)).empty());
}

}  // namespace
}  // namespace ret3d
