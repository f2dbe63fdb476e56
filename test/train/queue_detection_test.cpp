// The shipped detector (models/lwd3d/detector.pt) on a simulated stop-and-go queue in which every car is black (paint
// reflectivity 0.01-0.05: most of its returns read intensity 0 or are lost, as real dark cars' do): the car standing
// 3-8 m ahead in the ego's lane, seen from behind, is published in every frame (a Car box at the model's published
// threshold, its centre within 1 m of the car's). For a vehicle it is the most important object of the scene.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ret3d/detector/detector.h"
#include "ret3d/detector/model_file.h"
#include "ret3d/io/kitti.h"
#include "ret3d/io/sweeps.h"
#include "ret3d/sim/simulator.h"
#include "support/sim_info.h"
#include "support/test_util.h"

namespace ret3d {
namespace {

struct Ahead {
  bool present = false;
  double x = 0, y = 0;
};

// Per frame, the labelled car ahead in the ego's lane (test::isCarAhead).
std::vector<Ahead> carsAhead(const std::string& sim_info, int frames) {
  std::vector<Ahead> ahead(static_cast<std::size_t>(frames));
  for (const test::SimInfoRow& r : test::readSimInfo(sim_info))
    if (test::isCarAhead(r) && r.frame < frames) ahead[static_cast<std::size_t>(r.frame)] = {true, r.box.x, r.box.y};
  return ahead;
}

TEST(ShippedDetector, PublishesTheBlackCarAheadInAQueueInEveryFrame) {
  const std::string model = std::string(RET3D_SOURCE_DIR) + "/models/lwd3d/detector.pt";
  test::TempDir out;
  sim::SimOptions o;
  o.config = sim::loadSimConfig(std::string(RET3D_SOURCE_DIR) + "/config/sim/queue.yaml");
  o.config.paint = {sim::PaintMode{1.0, {0.01, 0.05}}};  // every car black
  o.sensor = sim::sensorByName("hdl64e", RET3D_SOURCE_DIR);
  o.out_dir = out.path();
  o.frames = 20;
  o.seed = 61;
  o.threads = 2;
  sim::simulateSequence(o, 0);
  const std::vector<Ahead> ahead = carsAhead(out / "training/sim_info/0000.txt", o.frames);

  DetectorOptions options = detectorOptionsForModel(model);
  Detector detector(options);
  const kitti::TrackingDataset ds(out.path());
  int frames_with_car = 0, published = 0;
  io::forEachSweep(ds, "0000", [&](const io::Sweep& s) {
    const Ahead& a = ahead[static_cast<std::size_t>(s.frame)];
    if (!a.present) return;
    ++frames_with_car;
    const Detections d = detector.detect(*s.cloud, s.previous, s.prev_to_current);
    bool found = false;
    double best_score = 0;
    for (const Box& b : d.boxes)
      if (b.label == ObjectClass::Car && std::hypot(b.x - a.x, b.y - a.y) < 1.0) {
        found = true;
        best_score = std::max(best_score, static_cast<double>(b.score));
      }
    published += found;
    EXPECT_TRUE(found) << "frame " << s.frame << ": no Car box on the black car " << a.x << " m ahead";
    if (found) EXPECT_GE(best_score, options.inference.scoreThreshold(ObjectClass::Car));
  });
  EXPECT_GE(frames_with_car, 15) << "the queue scene should put a car ahead in most frames";
  std::printf("  the black car ahead published in %d of %d frames\n", published, frames_with_car);
}

}  // namespace
}  // namespace ret3d
