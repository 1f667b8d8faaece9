// Seismic events from the break catalogue (host only; docs/case-format.md, "Outputs").
#pragma once
#include <vector>

#include "io/events_writer.hpp"

namespace fdem {

struct Model;

// Single linkage: two breaks belong to the same event when their midpoints are within
// `rule.distance` of each other (|Δx| <= distance) and their times within `rule.window`
// (|Δt| <= window); events are the connected groups (transitively). `breaks` must be in
// catalogue order (sorted by time, then CE4). Events come in the order of their first
// break in that order; each has its first and last time, the mean of its breaks'
// midpoints, the count, the sum of break_energy (added in catalogue order) and
// event_magnitude(energy). A break alone is an event of one break.
std::vector<io::EventRecord> group_events(const std::vector<io::BreakRecord>& breaks, const io::EventRule& rule);

// M = ⅔ (log10 E − 4.8) with E in J; NaN for E <= 0 (or not finite), never −inf.
double event_magnitude(double energy);

// The rule's defaults for a model: distance = 3 × the mean initial CE4 length, window =
// distance / the largest P-wave speed √(M/ρ) over the materials (M = λ + 2μ, or the
// hyperelastic wave modulus); a value the case gives (> 0) replaces its default.
io::EventRule event_rule(const Model& model, double distance, double window);

}  // namespace fdem
