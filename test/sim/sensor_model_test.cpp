#include "ret3d/sim/sensor_model.h"

#include <fstream>

#include <gtest/gtest.h>

#include "ret3d/sim/sim_config.h"
#include "support/error_message.h"
#include "support/test_util.h"

namespace ret3d {
namespace sim {
namespace {

TEST(SensorModel, PresetsMatchTheirDatasheets) {
  const SensorModel hdl = sensorByName("hdl64e", RET3D_SOURCE_DIR);
  EXPECT_EQ(hdl.beams(), 64);
  EXPECT_NEAR(hdl.elevation_deg.front(), -24.9, 1e-9);  // ring 0 is the lowest beam
  EXPECT_NEAR(hdl.elevation_deg.back(), 2.0, 1e-9);
  EXPECT_EQ(hdl.columns(), 2083);
  EXPECT_NEAR(hdl.mount_height, 1.73, 1e-9);
  const SensorModel vlp = sensorByName("vlp32c", RET3D_SOURCE_DIR);
  EXPECT_EQ(vlp.beams(), 32);
  EXPECT_NEAR(vlp.elevation_deg.front(), -25.0, 1e-9);
  EXPECT_NEAR(vlp.elevation_deg.back(), 15.0, 1e-9);
  const SensorModel os1 = sensorByName("os1_64", RET3D_SOURCE_DIR);
  EXPECT_EQ(os1.beams(), 64);
  EXPECT_EQ(os1.columns(), 1024);
  EXPECT_THROW(sensorByName("no_such_lidar", RET3D_SOURCE_DIR), std::runtime_error);
}

TEST(SensorModel, BadFileNamesTheKey) {
  test::TempDir dir;
  std::ofstream(dir / "bad.yaml") << "elevation_deg: [0, 1]\nazimuth_resolution: 0.2\n";
  const std::string msg = test::errorMessage([&] { loadSensorModel(dir / "bad.yaml"); });
  EXPECT_NE(msg.find("azimuth_resolution"), std::string::npos) << msg;
  EXPECT_NE(msg.find("bad.yaml"), std::string::npos) << msg;
  std::ofstream(dir / "range.yaml") << "elevation_deg: [0, 1]\nmin_range: 10\nmax_range: 5\n";
  EXPECT_THROW(loadSensorModel(dir / "range.yaml"), std::runtime_error);
}

TEST(SimConfig, PresetsLoadAndTyposAreErrors) {
  for (const char* name : {"urban_street", "highway", "queue"}) {
    const SimConfig c = loadSimConfig(std::string(RET3D_SOURCE_DIR) + "/config/sim/" + name + ".yaml");
    EXPECT_EQ(c.name, name);
    EXPECT_GT(c.traffic.car_density, 0);
    EXPECT_EQ(c.materials.size(), defaultMaterials().size());
  }
  test::TempDir dir;
  std::ofstream(dir / "typo.yaml") << "road:\n  lane_widht: 3.0\n";
  const std::string msg = test::errorMessage([&] { loadSimConfig(dir / "typo.yaml"); });
  EXPECT_NE(msg.find("road.lane_widht"), std::string::npos) << msg;
  std::ofstream(dir / "range.yaml") << "traffic:\n  car_speed: [10, 5]\n";
  EXPECT_THROW(loadSimConfig(dir / "range.yaml"), std::runtime_error);
}

}  // namespace
}  // namespace sim
}  // namespace ret3d
