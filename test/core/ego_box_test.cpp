#include "ret3d/core/ego_box.h"

#include <gtest/gtest.h>

#include "ret3d/core/option_range.h"

namespace ret3d {
namespace {

TEST(EgoBox, RemovesTheVehiclesOwnReturnsKeepingTimeAndRingAligned) {
  const EgoBox ego;  // KITTI's car, the sensor 1.73 m above base_link
  PointCloud cloud;
  // In the sensor frame: a mirror return beside the sensor, one on the bonnet, a car 8 m ahead, the road 5 m behind.
  cloud.push_back({0.2f, 1.0f, -0.7f, 0.3f}, 0.01f, 5, true);
  cloud.push_back({2.0f, 0.0f, -0.3f, 0.2f}, 0.02f, 20, true);
  cloud.push_back({8.0f, 0.0f, -1.0f, 0.5f}, 0.03f, 30, true);
  cloud.push_back({-5.0f, 0.5f, -1.73f, 0.1f}, 0.04f, 60, true);
  EXPECT_EQ(removePointsInside(ego, defaultSensorToBase(), &cloud), 2u);
  ASSERT_EQ(cloud.size(), 2u);
  ASSERT_TRUE(cloud.hasTime() && cloud.hasRing());
  EXPECT_FLOAT_EQ(cloud.points[0].x, 8.0f);
  EXPECT_FLOAT_EQ(cloud.time[0], 0.03f);
  EXPECT_EQ(cloud.ring[1], 60);
  // A sensor mounted 1 m further forward on the same car: a return 3.2 m behind it lies on the rear of the body.
  PointCloud behind;
  behind.push_back({-3.2f, 0.0f, -1.0f, 0.3f});
  EXPECT_EQ(removePointsInside(ego, Eigen::Isometry3d(Eigen::Translation3d(1.0, 0, 1.73)), &behind), 1u);
}

TEST(EgoBox, AnObjectAgainstTheBodyTouchesItOneFurtherAwayDoesNot) {
  const EgoBox ego;
  Box ped;
  ped.label = ObjectClass::Pedestrian;
  ped.length = 0.6, ped.width = 0.6, ped.height = 1.7, ped.z = -0.9;
  ped.x = 0.0, ped.y = 1.5;  // its side 1.2 m from the centre line: within 0.3 m of the body's 1.1 m
  EXPECT_TRUE(ego.touches(ped, defaultSensorToBase(), 0.3));
  ped.y = 2.0;  // 1.7 m: clear of the body and the margin
  EXPECT_FALSE(ego.touches(ped, defaultSensorToBase(), 0.3));
  Box car = ped;
  car.label = ObjectClass::Car;
  car.length = 4.5, car.width = 1.8, car.x = 6.0, car.y = 0.0, car.yaw = 0.0;  // 3.75 m ahead: its rear at 3.75 m
  EXPECT_FALSE(ego.touches(car, defaultSensorToBase(), 0.3));
  car.x = 4.8;  // its rear 2.55 m ahead of the sensor: against the bonnet's front (2.8 m)
  EXPECT_TRUE(ego.touches(car, defaultSensorToBase(), 0.3));
}

TEST(EgoBox, FromValuesRefusesWhatIsNotABox) {
  EXPECT_NO_THROW(EgoBox::fromValues({-2, 2, -1, 1, 0, 2}));
  for (const std::vector<double>& bad :
       std::vector<std::vector<double>>{{-2, 2, -1, 1}, {2, -2, -1, 1, 0, 2}, {-2, 2, -1, 1, 0, NAN}}) {
    try {
      EgoBox::fromValues(bad);
      FAIL() << "no error";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.key(), "ego_box");
    }
  }
  EXPECT_EQ(EgoBox::fromValues({-2, 2.5, -1, 1, 0, 2}).describe(), "[-2, 2.5, -1, 1, 0, 2]");
}

}  // namespace
}  // namespace ret3d
