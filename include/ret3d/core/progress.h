// The package's one progress bar for long command-line work: "label [=====>    ] 42/100  3.1 it/s  ETA 0:19  info".
// Draws to stderr, at most every 100 ms; on a non-terminal (CI logs) it prints a plain line every 10 %.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace ret3d {

class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total);
  ~ProgressBar();  // finishes the line
  // Advance by n; `info` is shown after the counts (e.g. the current losses).
  void tick(std::size_t n = 1, const std::string& info = "");
  // Advance by n steps done before this bar started (a resumed job): counted, but not in the rate.
  void skip(std::size_t n);
  void setInfo(const std::string& info);
  void finish();

 private:
  void draw(bool force);
  std::string label_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::size_t skipped_ = 0;
  std::string info_;
  bool tty_;
  bool finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace ret3d
