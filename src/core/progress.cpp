#include "ret3d/core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace ret3d {

ProgressBar::ProgressBar(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), tty_(isatty(fileno(stderr)) != 0) {
  start_ = last_draw_ = std::chrono::steady_clock::now();
  draw(true);
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::tick(std::size_t n, const std::string& info) {
  done_ += n;
  if (!info.empty()) info_ = info;
  draw(done_ >= total_);
}

void ProgressBar::skip(std::size_t n) {
  skipped_ += n;
  tick(n);
}

void ProgressBar::setInfo(const std::string& info) {
  info_ = info;
  draw(false);
}

void ProgressBar::finish() {
  if (finished_) return;
  draw(true);
  if (tty_) std::fputc('\n', stderr);
  finished_ = true;
}

void ProgressBar::draw(bool force) {
  if (finished_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double frac = total_ > 0 ? std::min(1.0, static_cast<double>(done_) / static_cast<double>(total_)) : 1.0;
  const double rate = elapsed > 0 ? (done_ - skipped_) / elapsed : 0.0;
  const double eta = rate > 0 && total_ > done_ ? (total_ - done_) / rate : 0.0;
  const int eta_s = static_cast<int>(eta + 0.5);
  if (tty_) {
    if (!force && now - last_draw_ < std::chrono::milliseconds(100)) return;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(frac * kWidth);
    std::string bar(kWidth, ' ');
    for (int i = 0; i < filled; ++i) bar[i] = '=';
    if (filled < kWidth) bar[filled] = '>';
    std::fprintf(stderr, "\r%s [%s] %zu/%zu  %.1f it/s  ETA %d:%02d  %s\033[K", label_.c_str(), bar.c_str(), done_,
                 total_, rate, eta_s / 60, eta_s % 60, info_.c_str());
  } else {
    const int decile = static_cast<int>(frac * 10);
    // Each tenth, and at least once a minute for long jobs (training) whose tenths are far apart.
    const bool minute = now - last_draw_ >= std::chrono::seconds(60);
    if (decile == last_decile_ && !minute && !(force && done_ >= total_ && last_decile_ < 10)) return;
    last_decile_ = decile;
    std::fprintf(stderr, "%s %3d%% %zu/%zu  %.1f it/s  %s\n", label_.c_str(), static_cast<int>(frac * 100), done_,
                 total_, rate, info_.c_str());
  }
  std::fflush(stderr);
  last_draw_ = now;
}

}  // namespace ret3d
