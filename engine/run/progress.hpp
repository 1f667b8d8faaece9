// The run's progress on the terminal: a live status line, or a line per tenth of the run.
#pragma once
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <ostream>

#include "base/format.hpp"

namespace fdem {

class Progress {
 public:
  Progress(std::ostream& log, bool status_line, long first, long steps)
      : log_(log), status_line_(status_line), first_(first), steps_(steps) {}
  // After step `s` (at time t [s]), `elapsed` [s] of wall time into the loop.
  void report(long s, double t, double elapsed) {
    const auto now = std::chrono::steady_clock::now();
    if (status_line_ && (std::chrono::duration<double>(now - last_report_).count() > 0.5 || s == steps_)) {
      last_report_ = now;
      const double rate = (s - first_) / std::max(elapsed, 1e-9);
      log_ << "\rstep " << s << "/" << steps_ << "  t = " << format_number(t) << " s  " << std::fixed
           << std::setprecision(1) << 100.0 * s / steps_ << "%  " << std::setprecision(0) << rate << " steps/s  ETA "
           << std::setprecision(1) << (steps_ - s) / rate << " s   " << std::defaultfloat << std::flush;
    } else if (!status_line_) {
      const int decile = static_cast<int>(10 * s / steps_);
      if (decile > last_decile_) {
        last_decile_ = decile;
        log_ << "  " << decile * 10 << "%  step " << s << "/" << steps_ << "  t = " << format_number(t) << " s  "
             << std::fixed << std::setprecision(0) << (s - first_) / std::max(elapsed, 1e-9) << " steps/s"
             << std::defaultfloat << "\n" << std::flush;
      }
    }
  }

 private:
  std::ostream& log_;
  bool status_line_;
  long first_, steps_;
  std::chrono::steady_clock::time_point last_report_ = std::chrono::steady_clock::now();
  int last_decile_ = 0;
};

}  // namespace fdem
