#include <algorithm>
#include <cmath>

#include "engine/outputs/output.hpp"

namespace fdem {

Trigger Trigger::at_steps(std::vector<long> steps) {
  Trigger t(Kind::Steps);
  t.steps_ = std::move(steps);
  return t;
}

Trigger Trigger::every_steps(long n, long last) {
  Trigger t(Kind::Every);
  t.every_ = std::max(1L, n);
  t.last_ = last;
  return t;
}

// The first multiple of `period` after time t, reckoned (never a loop of additions, which
// makes no progress once the period is below the resolution of t).
static double multiple_after(double t, double period) {
  const double next = (std::floor(t / period + 1e-9) + 1) * period;
  return next > t ? next : std::nextafter(t, HUGE_VAL);
}

Trigger Trigger::every_seconds(double period, double dt, double start) {
  if (!(period > 0)) return never();
  Trigger t(Kind::Seconds);
  t.period_ = period, t.dt_ = dt;
  t.next_ = multiple_after(start, period);
  return t;
}

Trigger Trigger::any_of(std::vector<const Trigger*> triggers) {
  Trigger t(Kind::AnyOf);
  t.any_ = std::move(triggers);
  return t;
}

bool Trigger::due(long step, double time) const {
  switch (kind_) {
    case Kind::Never: return false;
    case Kind::Steps: return std::binary_search(steps_.begin(), steps_.end(), step);
    case Kind::Every: return step > 0 && (step % every_ == 0 || step == last_);
    case Kind::Seconds: return time >= next_ - 1e-6 * dt_;
    case Kind::AnyOf:
      return std::any_of(any_.begin(), any_.end(), [&](const Trigger* t) { return t->due(step, time); });
  }
  return false;
}

bool Trigger::on_schedule(long step) const {
  switch (kind_) {
    case Kind::Steps: return std::binary_search(steps_.begin(), steps_.end(), step);
    case Kind::Every: return step % every_ == 0;
    default: return false;
  }
}

void Trigger::passed(double time) {
  if (kind_ == Kind::Seconds) next_ = multiple_after(time + 1e-6 * dt_, period_);
}

}  // namespace fdem
