#include "engine/outputs/fracture_events.hpp"

#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "engine/model/model.hpp"

namespace fdem {

namespace {

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

double event_magnitude(double energy) {
  if (!(energy > 0.0) || !std::isfinite(energy)) return std::numeric_limits<double>::quiet_NaN();
  return 2.0 / 3.0 * (std::log10(energy) - 4.8);
}

std::vector<io::EventRecord> group_events(const std::vector<io::BreakRecord>& breaks, const io::EventRule& rule) {
  const int n = static_cast<int>(breaks.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  // Breaks come in time order: a sweep keeps those within the window behind the current
  // one in a grid of cells of side `distance`, so each break is compared with the breaks
  // of its own and the eight neighbouring cells only.
  const double d = rule.distance, d2 = d * d;
  const bool grid = d > 0.0;
  auto cell_of = [&](double v) { return grid ? static_cast<long long>(std::floor(v / d)) : 0LL; };
  auto key = [](long long cx, long long cy) { return (cx * 73856093LL) ^ (cy * 19349663LL); };
  std::unordered_map<long long, std::deque<int>> cells;
  std::deque<int> alive;  // in the window, oldest first
  for (int i = 0; i < n; ++i) {
    const auto& b = breaks[i];
    while (!alive.empty() && breaks[alive.front()].time < b.time - rule.window) {
      const int old = alive.front();
      alive.pop_front();
      auto& c = cells[key(cell_of(breaks[old].x), cell_of(breaks[old].y))];
      // Cells receive breaks in time order, so the oldest leaves from the front.
      if (!c.empty() && c.front() == old) c.pop_front();
      else
        for (auto it = c.begin(); it != c.end(); ++it)
          if (*it == old) {
            c.erase(it);
            break;
          }
    }
    const long long cx = cell_of(b.x), cy = cell_of(b.y);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy) {
        const auto it = cells.find(key(cx + dx, cy + dy));
        if (it == cells.end()) continue;
        for (int j : it->second) {
          const double ex = breaks[j].x - b.x, ey = breaks[j].y - b.y;
          if (ex * ex + ey * ey <= d2) {
            const int ri = find_root(parent, i), rj = find_root(parent, j);
            if (ri != rj) parent[std::max(ri, rj)] = std::min(ri, rj);  // the root is the group's first break
          }
        }
      }
    cells[key(cx, cy)].push_back(i);
    alive.push_back(i);
  }
  std::vector<io::EventRecord> events;
  std::vector<int> index(n, -1);  // root → event
  std::vector<double> sx, sy;
  for (int i = 0; i < n; ++i) {
    const int r = find_root(parent, i);
    if (index[r] < 0) {
      index[r] = static_cast<int>(events.size());
      io::EventRecord e;
      e.start = e.end = breaks[i].time;
      events.push_back(e);
      sx.push_back(0.0), sy.push_back(0.0);
    }
    const int k = index[r];
    auto& e = events[k];
    e.start = std::min(e.start, breaks[i].time);
    e.end = std::max(e.end, breaks[i].time);
    sx[k] += breaks[i].x, sy[k] += breaks[i].y;
    e.energy += breaks[i].energy;
    ++e.breaks;
  }
  for (size_t k = 0; k < events.size(); ++k) {
    events[k].x = sx[k] / double(events[k].breaks);
    events[k].y = sy[k] / double(events[k].breaks);
    events[k].magnitude = event_magnitude(events[k].energy);
  }
  return events;
}

io::EventRule event_rule(const Model& model, double distance, double window) {
  io::EventRule rule;
  double sum = 0;
  for (const auto& c : model.ce4) sum += std::hypot(model.x[c[1]] - model.x[c[0]], model.y[c[1]] - model.y[c[0]]);
  const double mean = model.ce4.empty() ? 0.0 : sum / double(model.ce4.size());
  rule.distance = distance > 0 ? distance : 3.0 * mean;
  double vp = 0;
  for (const auto& m : model.materials)
    if (m.density > 0) vp = std::max(vp, std::sqrt(m.wave_modulus / m.density));
  rule.window = window > 0 ? window : (vp > 0 ? rule.distance / vp : 0.0);
  return rule;
}

}  // namespace fdem
