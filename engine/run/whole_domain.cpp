// The model on one device (engine/run/domain.hpp). A read's conditions, energy account,
// positions and forces are queued together and land with one wait (RowReads).
#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/run/domain.hpp"

namespace fdem {

namespace {

// Each probe's (vx, vy, sxx, syy, sxy, ps1): evaluates the stress of the current state
// (one triangle-force pass) and reads back each probe's velocity (one real2) and stress
// (one real4). Waits for the queue.
std::vector<double> probe_values(Solver& solver, const PointProbes& probes) {
  std::vector<double> row;
  if (probes.empty()) return row;
  solver.enqueue_stress();
  auto& queue = solver.context().queue();
  const auto& arrays = solver.arrays();
  for (const auto& p : probes.locations()) {
    real2 v;
    real4 s;
    queue.enqueue_read_buffer(arrays.velocity, p.node * sizeof(real2), sizeof(real2), &v);
    queue.enqueue_read_buffer(arrays.stress, p.triangle * sizeof(real4), sizeof(real4), &s);
    const double sxx = s.x, syy = s.y, sxy = s.z;
    const double ps1 = 0.5 * (sxx + syy) + std::hypot(0.5 * (sxx - syy), sxy);
    row.insert(row.end(), {double(v.x), double(v.y), sxx, syy, sxy, ps1});
  }
  return row;
}

// The profile's split of a snapshot read (host wall between laps; nothing when not profiling).
class Laps {
 public:
  explicit Laps(ClContext& cl) : cl_(cl), last_(std::chrono::steady_clock::now()) {}
  void operator()(const char* what) {
    if (!cl_.profiling()) return;
    const auto now = std::chrono::steady_clock::now();
    cl_.add_host_time(std::string("  snapshot read: ") + what, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  ClContext& cl_;
  std::chrono::steady_clock::time_point last_;
};

class WholeDomain : public Domain {
 public:
  WholeDomain(const PreparedCase& p, ClContext& cl) : p_(p), cl_(cl), probes_(p.probes) {
    solver_ = std::make_unique<Solver>(cl, p.model, p.dt);
  }
  bool writes_files() const override { return true; }
  void after_step() override {}
  Snapshot read(Needs needs) override;
  void agree(std::exception_ptr failure) override {
    if (failure) std::rethrow_exception(failure);
  }
  StopRequest agree_stop(StopRequest mine, bool) override { return mine; }
  bool stops_alone() const override { return true; }
  void load(const io::CheckpointData& whole, const std::string& path) override {
    StateReader in(cl_, whole, path);
    solver_->load_state(in);
  }

 private:
  const PreparedCase& p_;
  ClContext& cl_;
  const PointProbes probes_;
};

Snapshot WholeDomain::read(Needs needs) {
  Solver& solver = *solver_;
  CohesiveForces* const ce4 = solver.cohesive();
  Snapshot s;
  s.step = solver.steps_done(), s.time = solver.time(), s.has = needs;
  Laps lap(cl_);
  RowReads& reads = solver.row_reads();
  reads.begin();
  std::function<Conditions()> conditions;
  std::function<EnergyTotals()> energy;
  std::function<std::vector<real2>()> positions, forces;
  if (needs.has(Need::Conditions)) conditions = solver.queue_conditions();
  if (needs.has(Need::Energy)) energy = solver.queue_energy();
  if (needs.has(Need::Positions)) positions = solver.queue_positions();
  if (needs.has(Need::Forces)) forces = solver.queue_forces();
  if (conditions) {
    s.conditions = conditions();
    lap("conditions (the wait for the queue)");
    if (!s.passed()) return s;
  }
  if (ce4 && needs.has(Need::Breaks)) {
    const auto began = std::chrono::steady_clock::now();
    s.breaks = with_triangles(p_.model, ce4->drain_breaks());
    if (cl_.profiling())
      cl_.add_host_time("break catalogue (host wall: count and records read, sort, events file append)",
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
  }
  if (ce4 && needs.has(Need::Catalogue)) s.breaks = with_triangles(p_.model, ce4->catalogue());
  lap("breaks");
  if (energy) {
    s.energy = energy();
    s.energy_error = solver.balance().error(s.energy);
    s.energy_ratio = solver.balance().ratio(s.energy);
    s.energy_time = solver.energy_time();
  }
  lap("energy");
  if (positions) s.positions = positions();
  if (forces) s.forces = forces();
  lap("positions and forces");
  if (needs.has(Need::Velocities)) s.velocities = solver.velocities();
  if (needs.has(Need::ContactCounts)) {
    s.contact_touching = solver.contact_touching();
    s.contact_candidates = solver.contact_candidates();
    s.contact_rebuilds = solver.contact_rebuilds();
  }
  lap("velocities, contact counts");
  bool stress_current = false;  // the probes evaluate the stress of this state
  if (needs.has(Need::Probes)) s.probes = probe_values(solver, probes_), stress_current = !probes_.empty();
  if (needs.has(Need::Stress)) {
    if (!stress_current) solver.enqueue_stress();
    s.stress = solver.stresses();
  }
  if (needs.has(Need::ContactForces) && solver.has_contact()) s.contact_forces = solver.contact_forces();
  if (ce4 && needs.has(Need::Ce4State)) s.damage = ce4->damage(), s.opening = ce4->opening(), s.slip = ce4->slip();
  lap("probes, stress, contact forces, CE4 state");
  if (ce4 && (needs.has(Need::Ce4Flags) || needs.has(Need::FragmentLabels))) {
    ce4->flags(s.broken, s.mode);
    s.inserted_ce4 = static_cast<long>(ce4->count_inserted());
  }
  lap("CE4 flags");
  if (needs.has(Need::FluidSegments) && solver.fluid()) solver.fluid()->segment_fields(s.fluid_pressure, s.fluid_aperture);
  // The pieces, reused while no CE4 broke since the last labelling.
  if (ce4 && needs.has(Need::FragmentLabels))
    s.labels = solver.fragment_labels(static_cast<long>(std::count_if(s.broken.begin(), s.broken.end(), [](int b) { return b != 0; })));
  lap("fragment labels");
  if (needs.has(Need::State)) {
    const auto began = std::chrono::steady_clock::now();
    StateWriter out(cl_, s.state);
    solver.save_state(out);
    s.broken_ce4 = ce4 ? static_cast<long>(ce4->count_broken()) : 0;
    s.state_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  }
  if (needs.has(Need::Masses)) s.masses = solver.masses();
  return s;
}

}  // namespace

std::unique_ptr<Domain> make_whole_domain(const PreparedCase& p, ClContext& cl) {
  return std::make_unique<WholeDomain>(p, cl);
}

}  // namespace fdem
