// The history file's columns as one table: each column is one entry {name, unit,
// description, value}, so a new history variable is one line in history.cpp. The values of
// a row come from a Snapshot read with the table's needs().
#pragma once
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/energy/energy.hpp"
#include "engine/outputs/fragments.hpp"
#include "engine/model/model.hpp"
#include "engine/outputs/snapshot.hpp"
#include "engine/model/probes.hpp"
#include "engine/model/real.hpp"
#include "io/history_writer.hpp"

namespace fdem {

// One history row's data: a Snapshot read with the table's needs (HistoryTable::needs),
// and what several columns compute from it, computed once.
class HistoryRow {
 public:
  explicit HistoryRow(const Snapshot& snap) : snap(snap) {}
  // The pieces of the body (the snapshot's fragment labels and positions); models with CE4s.
  const PieceAreas& pieces(const Model& model);

  const Snapshot& snap;
  std::optional<std::array<double, 2>> unbalance;  // (largest free component, mean internal), once computed

 private:
  std::optional<PieceAreas> pieces_;
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
  // What a row of `model`'s history reads (Domain::read).
  static Needs needs(const Model& model, const PointProbes& probes);
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
