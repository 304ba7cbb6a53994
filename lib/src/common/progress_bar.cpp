#include "alvio/common/progress_bar.h"

#include <unistd.h>

#include <cstdio>

namespace alvio {

ProgressBar::ProgressBar(std::string label, std::size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() {
  if (!finished_) finish();
}

void ProgressBar::update(std::size_t done, const std::string& extra) {
  if (!enabled_ || total_ == 0) return;
  const auto now = std::chrono::steady_clock::now();
  const int percent = static_cast<int>(100.0 * done / total_);
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const double eta = rate > 0 ? (total_ - done) / rate : 0.0;
  if (tty_) {
    // Redraw at most 10 times a second.
    if (std::chrono::duration<double>(now - last_draw_).count() < 0.1 && done < total_) return;
    last_draw_ = now;
    const int width = 30;
    const int filled = width * percent / 100;
    std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% %zu/%zu %.1f/s ETA %.0fs %s\033[K", label_.c_str(),
                 filled, "##############################", width - filled, "", percent, done,
                 total_, rate, eta, extra.c_str());
  } else {
    if (percent / 10 == last_percent_ / 10 && done < total_) return;
    std::fprintf(stderr, "%s: %3d%% %zu/%zu %.1f/s ETA %.0fs %s\n", label_.c_str(), percent, done,
                 total_, rate, eta, extra.c_str());
  }
  last_percent_ = percent;
  std::fflush(stderr);
}

void ProgressBar::finish(const std::string& extra) {
  if (finished_) return;
  finished_ = true;
  if (!enabled_ || total_ == 0) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (tty_) std::fprintf(stderr, "\r\033[K");
  std::fprintf(stderr, "%s: done, %zu items in %.1f s %s\n", label_.c_str(), total_, elapsed,
               extra.c_str());
  std::fflush(stderr);
}

}  // namespace alvio
