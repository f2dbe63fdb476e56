// `ret3d bench --bag FILE` (the default with a bag): the pipeline timed as it runs online. This process becomes the
// nodelet manager: it loads the real stage nodelets (ret3d/DetectorNodelet, IntraRMNodelet, TrackerNodelet,
// InterRMNodelet, MarkerNodelet) with the parameters and topics of launch/ret3d.launch, while a player process (forked
// from this one, so the clouds cross a process boundary as they do from a driver or `rosbag play`) publishes the bag's
// clouds at the bag's rate, restamped by one constant offset to the wall clock, with the bag's /tf restamped alike and
// /tf_static as it is. The manager records when each stage's output arrives for each cloud stamp: per-stage times,
// end-to-end latency (cloud stamp to /objects), frames without output, and the CPU the manager process used.
// A private ROS master (rosmaster --core on a free port) keeps the run apart from any ROS system on the machine.
// The soak (--loop-frames) plays the bag in a loop and samples this process, the one hosting the nodelets, as it goes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace ret3d {
namespace tools {

struct NodeletBenchOptions {
  std::string bag;
  std::string topic;                // the bag's PointCloud2 topic (default: the first)
  std::vector<std::string> stages;  // parseStages(): base first; "inter" implies the tracker
  std::string detector_model, intra_model, inter_model;  // resolved files (existence checked by the caller)
  std::string detector_config;      // empty: the config stored in the detector's model file
  std::string tracker_config;       // empty: the one config/ret3d.yaml names
  std::string params;               // the nodelets' YAML (default: $(find ret3d)/config/ret3d.yaml)
  double score_threshold = -1;      // >= 0: overrides ret3d_detector/score_threshold
  std::vector<double> grid_extent;  // non-empty: sets ret3d_detector/grid_extent
  int threads = 2;                  // libtorch threads of each learned stage (the launch file's `threads`)
  int manager_threads = 4;          // the manager's callback threads (the launch file's `manager_threads`)
  bool markers = true;              // load the MarkerNodelet too, as the launch file does (only with InterRM)
  double rate = 1.0;                // playback speed factor (rosbag play -r)
  int warmup = 5;                   // first clouds left out of the statistics
  int max_frames = 200;             // clouds played at most
  double tail = 3.0;                // s to wait after the last cloud for its outputs
  std::string json;                 // results file (empty: none)
  // Soak: > 0 plays the bag in a loop (each pass one period after the last, stamps always increasing) until this many
  // clouds have been played, and every `soak_every` clouds samples this process's resident memory, open file
  // descriptors and threads and the latencies of the clouds since the last sample (tools/nodelet_bench.cpp).
  int loop_frames = 0;
  int soak_every = 500;
  int load = 0;                     // cores kept busy by spinning child processes during the replay (BusyLoad)
};

// What the caller compares between runs (e.g. `--baseline`): milliseconds, -1 when not measured.
struct NodeletBenchResult {
  double base_p50 = -1, base_p95 = -1;                        // cloud in the manager to /detections, waiting included
  double base_processing_p50 = -1, base_processing_p95 = -1;  // the detector's own /diagnostics
  double end_to_end_p50 = -1, end_to_end_p95 = -1;
  std::size_t frames = 0, dropped = 0;
};

// N processes that spin on a core each while the object lives: a reproducible "other work" for latency under load.
// They end with this process too (PR_SET_PDEATHSIG), so no spinner outlives a bench that was killed.
class BusyLoad {
 public:
  explicit BusyLoad(int processes);
  BusyLoad(const BusyLoad&) = delete;
  BusyLoad& operator=(const BusyLoad&) = delete;
  ~BusyLoad();

 private:
  std::vector<int> pids_;
};

// Runs the bench; prints the table; returns the exit code. Throws std::runtime_error naming what is wrong (the bag,
// a nodelet that did not start, no ROS master).
// With --loop-frames, the soak: see NodeletBenchOptions::loop_frames; the JSON holds the samples and the checks.
int runNodeletBench(const NodeletBenchOptions& options, NodeletBenchResult* result = nullptr);

}  // namespace tools
}  // namespace ret3d
