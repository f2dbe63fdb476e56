// The simulator's per-object ground truth (training/sim_info/SSSS.txt, docs/SIMULATOR.md) as the tests read it:
// frame track class x y z length width height yaw vx vy num_points ... in the LiDAR frame.
#pragma once

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ret3d/core/types.h"

namespace ret3d {
namespace test {

struct SimInfoRow {
  int frame = 0;
  int track = 0;
  std::string type;
  Box box;  // x, y, z (bottom centre), length, width, height, yaw, vx, vy, num_points
};

// Every object line of a sim_info file; a line that does not parse fails the calling test.
inline std::vector<SimInfoRow> readSimInfo(const std::string& path) {
  std::vector<SimInfoRow> rows;
  std::ifstream f(path);
  EXPECT_TRUE(f.good()) << "cannot read " << path;
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    SimInfoRow r;
    Box& b = r.box;
    s >> r.frame >> r.track >> r.type >> b.x >> b.y >> b.z >> b.length >> b.width >> b.height >> b.yaw >> b.vx >>
        b.vy >> b.num_points;
    EXPECT_FALSE(s.fail()) << line;
    rows.push_back(r);
  }
  return rows;
}

// A car in the ego's lane heading its way with its rear 3-8 m ahead of the sensor (a queue's car ahead).
inline bool isCarAhead(const SimInfoRow& r) {
  const Box& b = r.box;
  const double rear = b.x - 0.5 * b.length * std::abs(std::cos(b.yaw));
  return r.type == "Car" && std::abs(b.y) < 1.2 && std::cos(b.yaw) > 0.9 && rear > 3 && rear < 8;
}

}  // namespace test
}  // namespace ret3d
