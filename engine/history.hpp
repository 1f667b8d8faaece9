// The history file's columns as one table: each column is one entry {name, unit,
// description, value}, so a new history variable is one line in history.cpp. The values of
// a row come from a HistoryRow, which fetches what the columns read from the device once.
#pragma once
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/energy.hpp"
#include "engine/fragments.hpp"
#include "engine/model.hpp"
#include "engine/probes.hpp"
#include "engine/real.hpp"
#include "io/history_writer.hpp"

namespace fdem {

class Solver;

// One history row's data: the energy account (given), the rest read from the device on
// first use and shared by every column that needs it.
class HistoryRow {
 public:
  HistoryRow(Solver& solver, const PointProbes& probes, const EnergyTotals& energy, double error, double ratio)
      : energy(energy), energy_error(error), energy_ratio(ratio), solver_(solver), probes_(probes) {}

  Solver& solver() { return solver_; }
  const std::vector<real2>& positions();
  const std::vector<real2>& forces();  // out-of-balance force of the last step (incl. gravity)
  const std::vector<int>& broken();
  const std::vector<int>& mode();
  const std::vector<double>& probe_values();  // PointProbes::values, in their order
  // The pieces of the body now (Solver::fragment_labels and the positions); models with CE4s.
  const FragmentSummary& fragments(const Model& model);
  // Whether this row evaluated the stress of the current state (for the probes): a frame
  // written at the same step then need not evaluate it again.
  bool stress_evaluated() const { return probe_values_.has_value() && !probes_.empty(); }
  // A split run: the whole model's positions, forces, CE4 flags and fragment labels,
  // gathered in global order (rank 0), used instead of the solver's.
  void provide(std::vector<real2> positions, std::vector<real2> forces, std::vector<int> broken, std::vector<int> mode,
               std::vector<int> labels) {
    positions_ = std::move(positions), forces_ = std::move(forces), broken_ = std::move(broken), mode_ = std::move(mode);
    labels_ = std::move(labels);
  }
  // One rank: the positions and forces as reads already queued (Solver::queue_positions,
  // queue_forces), so that they land with the row's other reads.
  void prefetch(std::function<std::vector<real2>()> positions, std::function<std::vector<real2>()> forces) {
    pending_positions_ = std::move(positions), pending_forces_ = std::move(forces);
  }
  // A split run: the probes' values gathered on rank 0 (SplitRun::probe_values), the
  // stress having been evaluated on every rank.
  void provide_probes(std::vector<double> values) { probe_values_ = std::move(values); }

  const EnergyTotals energy;
  const double energy_error, energy_ratio;
  std::optional<std::array<double, 2>> unbalance;  // (largest free component, mean internal), once computed

 private:
  Solver& solver_;
  const PointProbes& probes_;
  std::optional<std::vector<real2>> positions_, forces_;
  std::function<std::vector<real2>()> pending_positions_, pending_forces_;
  std::optional<std::vector<int>> broken_, mode_;
  std::optional<std::vector<double>> probe_values_;
  std::optional<FragmentSummary> fragments_;
  std::optional<std::vector<int>> labels_;
};

struct HistoryColumn {
  io::HistoryVariable variable;
  std::function<double(HistoryRow&)> value;
};

class HistoryTable {
 public:
  // The columns of `model`'s history: energy account, out-of-balance force, contact and
  // fracture counts when the model has them, reactions and mean displacements of regions,
  // then the [[probe]] values. `masses`: (lumped mass, inertia) per node.
  HistoryTable(const Model& model, const std::vector<real2>& masses, const PointProbes& probes);
  std::vector<io::HistoryVariable> variables() const;
  std::vector<double> values(HistoryRow& row) const;
  // Index of a column by name (for summaries), or -1.
  int index(const std::string& name) const;

 private:
  std::vector<HistoryColumn> columns_;
};

// A region's name as a netCDF variable prefix (letters, digits, '_').
std::string netcdf_name(const std::string& region);

}  // namespace fdem
