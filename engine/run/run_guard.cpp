#include "engine/run/run_guard.hpp"

#include <cmath>
#include <sstream>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/run/split_run.hpp"

namespace fdem {

namespace {

std::string describe_failure(const Model& model, const Conditions& c) {
  std::ostringstream msg;
  if (c.bad_node >= 0) {
    msg << "step " << c.bad_node_step << ": node " << model.node_tags[c.bad_node] << " (at "
        << model.x[c.bad_node] << ", " << model.y[c.bad_node]
        << ") got a non-finite position or velocity; the time step may be unstable or a load too large";
  } else {
    const auto& tri = model.triangles[c.inverted_triangle];
    msg << "step " << c.inverted_step << ": triangle " << model.triangle_tags[c.inverted_triangle]
        << " (material '" << model.materials[model.triangle_material[c.inverted_triangle]].name
        << "', nodes " << model.node_tags[tri[0]] << " " << model.node_tags[tri[1]] << " "
        << model.node_tags[tri[2]] << ") inverted (J <= 0)";
  }
  return msg.str();
}

}  // namespace

void RunGuard::check(Snapshot& snap, Domain& domain, OutputSet& outputs, const OutputSet::Due& due) {
  if (snap.has.has(Need::Conditions) && !snap.passed()) {
    failure_agreed() = true;  // every rank of a split run found the same
    const std::string what = describe_failure(p_.model, snap.conditions);
    std::string saved;
    if (domain.has_good_copy()) {
      domain.restore_good_copy();
      try {
        if (domain.solver().steps_done() != outputs.last_frame_step()) outputs.write_frame(domain.read(outputs.frame_needs()));
        saved = "; the last good state (step " + std::to_string(domain.solver().steps_done()) + ", t = " +
                format_number(domain.solver().time()) + " s) is the last frame of " + p_.exodus_path;
      } catch (const std::exception&) {
        saved = "";  // the stress of the last good state may itself be invalid
      }
    }
    if (status_line_) log_ << "\n";
    throw NumericalError(what + saved);
  }
  if (snap.has.has(Need::Energy)) {
    const double error = snap.energy_error;
    worst_ = std::max(worst_, std::fabs(error));
    final_ = error;
    const std::string grew = EnergyBalance::largest_change(last_energy_, snap.energy);
    last_energy_ = snap.energy;
    snap.worst_energy_error = worst_;
    const double limit = p_.config.output.energy_limit;
    if (std::fabs(error) > limit) {
      failure_agreed() = true;  // the account is the same on every rank
      outputs.write_records(due, snap);  // the row that passed the limit is kept
      if (status_line_) log_ << "\n";
      std::string saved;
      try {
        if (snap.step != outputs.last_frame_step()) outputs.write_frame(domain.read(outputs.frame_needs()));
        saved = "; the state at this step is the last frame of " + p_.exodus_path;
      } catch (const std::exception&) {
      }
      throw NumericalError("step " + std::to_string(snap.step) + ", t = " + format_number(snap.energy_time) +
                           " s: energy_error " + format_number(error, 3) + " exceeds output.energy_limit = " +
                           format_number(limit, 3) + " (the energy balance does not close; " + grew +
                           " changed most since the last history row)" + saved);
    }
    if (std::fabs(error) > 0.01 && !warned_) {
      warned_ = true;
      if (status_line_) log_ << "\n";
      log_ << "warning: step " << snap.step << ", t = " << format_number(snap.energy_time) << " s: energy_error "
           << format_number(error, 3) << " is above 1% (" << grew << " changed most since the last history row)\n";
    }
  }
  snap.worst_energy_error = worst_;
}

}  // namespace fdem
