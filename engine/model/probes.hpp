// History probes ([[probe]] entries): points of the mesh whose velocity and stress the
// history file records every row. Each point is tied once, on the host, to its nearest
// node (velocity) and to the triangle containing it (stress); a history row then reads
// back only those few values, not whole arrays.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "engine/model/model.hpp"
#include "io/case_config.hpp"
#include "io/history_writer.hpp"

namespace fdem {

struct ProbeLocation {
  std::string name;
  std::array<double, 2> point{0, 0};  // [m], as given
  int node = -1;                      // nearest node (lowest index among equally near ones)
  int triangle = -1;                  // triangle containing the point
  double node_distance = 0;           // |point - node| [m]
};

// Ties each probe to its node and triangle. A point on an edge or a corner belongs to
// the lowest-numbered triangle that holds it; a point within 1% of a triangle's longest
// edge outside the mesh (a probe put on a curved boundary meshed with chords) belongs
// to the nearest triangle. Throws InputError naming the case file and the probe for a
// point farther outside, giving the distance and the nearest point of the mesh.
std::vector<ProbeLocation> locate_probes(const Model& model, const std::vector<io::ProbeConfig>& probes,
                                         const std::string& case_path);

// The probes' history variables and values: <name>_vx, _vy [m/s] of the node and
// <name>_sxx, _syy, _sxy, _ps1 [Pa] of the triangle, in that order per probe.
class PointProbes {
 public:
  explicit PointProbes(std::vector<ProbeLocation> locations) : locations_(std::move(locations)) {}

  std::vector<io::HistoryVariable> variables(const Model& model) const;
  // The values of a row, per probe (vx, vy, sxx, syy, sxy, ps1), are read by the domain
  // (engine/run/whole_domain.cpp, SplitRun::probe_values).
  const std::vector<ProbeLocation>& locations() const { return locations_; }
  bool empty() const { return locations_.empty(); }

 private:
  std::vector<ProbeLocation> locations_;
};

}  // namespace fdem
