// Internal to src/eval: a minimal parallel-for over independent work items (the evaluation's classes, difficulties
// and frame blocks), so a full benchmark evaluates in seconds on the two cores the package targets.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace ret3d {
namespace eval {
namespace detail {

// Runs fn(i) for i in [0, n) on up to `threads` threads; rethrows the first exception after all have stopped.
inline void parallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& fn) {
  const std::size_t workers = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(1, threads)));
  if (workers <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&]() {
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        fn(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// Serialises progress callbacks coming from worker threads.
class ProgressCounter {
 public:
  ProgressCounter(std::function<void(std::size_t, std::size_t)> cb, std::size_t total)
      : cb_(std::move(cb)), total_(total) {}
  void tick() {
    if (!cb_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    cb_(++done_, total_);
  }

 private:
  std::function<void(std::size_t, std::size_t)> cb_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::mutex mutex_;
};

}  // namespace detail
}  // namespace eval
}  // namespace ret3d
