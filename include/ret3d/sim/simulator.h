// The simulator's main loop: per sequence, lay out a scene, spawn (or replay) the traffic, and for every frame move
// the actors, cast a sweep, label it and write it (sequence_writer.h).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "ret3d/sim/sensor_model.h"
#include "ret3d/sim/sim_config.h"

namespace ret3d {
namespace sim {

struct SimOptions {
  SimConfig config;
  SensorModel sensor;
  std::string out_dir;
  int frames = 100;             // per sequence (replay: at most this many; <= 0 = all)
  std::uint64_t seed = 0;
  int threads = 2;
  // Replay of a KITTI tracking sequence (empty = procedural traffic).
  std::string replay_dir, replay_sequence;
};

struct FrameReport {
  int sequence = 0, frame = 0;
  std::size_t points = 0;
  std::size_t objects = 0;
  std::size_t objects_within_50m = 0;
  double seconds = 0;           // wall time of the frame: motion, casting, labelling and writing
};

struct SequenceReport {
  std::string name;             // SSSS
  std::vector<FrameReport> frames;
  std::map<std::string, std::size_t> objects;   // labelled object-frames per class
  std::map<std::string, std::size_t> tracks;    // distinct labelled tracks per class
  std::size_t object_points = 0;                // sum of num_points over labelled object-frames
  std::size_t static_triangles = 0;
  double setup_seconds = 0;     // scene layout, BVH build, spawning
};

// Simulates sequence `index` (written as SSSS = index) with seed options.seed + index; calls `on_frame` after each.
SequenceReport simulateSequence(const SimOptions& options, int index,
                                const std::function<void(const FrameReport&)>& on_frame = {});

}  // namespace sim
}  // namespace ret3d
