// The model split over the ranks of `mpirun` (engine/run/domain.hpp, engine/run/split_run.*):
// each rank steps its share; a read gathers the whole model to rank 0 in global order,
// and the sums of the account are taken by one rule, so the files are one rank's.
#include <algorithm>
#include <chrono>

#include "engine/run/domain.hpp"
#include "engine/run/split_run.hpp"

namespace fdem {

namespace {

class SplitDomain : public Domain {
 public:
  SplitDomain(const PreparedCase& p, ClContext& cl, Transport& transport, PartitionMethod partition, double travel)
      : p_(p), cl_(cl), transport_(transport) {
    split_ = std::make_unique<SplitRun>(p.model, transport, partition, travel);
    solver_ = std::make_unique<Solver>(cl, split_->local_model(), p.dt);
    split_->attach(cl, *solver_);
  }
  bool writes_files() const override { return split_->root(); }
  void after_step() override { split_->exchange(); }
  Snapshot read(Needs needs) override;
  void agree(std::exception_ptr failure) override { fdem::agree(transport_, failure); }
  StopRequest agree_stop(StopRequest mine, bool talk) override {
    // Every rank must stop at the same step: a signal or --max-wall on any rank counts at
    // the next step where the ranks talk anyway.
    if (!talk) return {};
    return {static_cast<int>(transport_.max(mine.signal)), transport_.max(mine.out_of_time ? 1 : 0) != 0};
  }
  bool stops_alone() const override { return false; }
  void load(const io::CheckpointData& whole, const std::string& path) override {
    const io::CheckpointData local = split_->local_state(whole);
    StateReader in(cl_, local, path);
    solver_->load_state(in);
  }

 private:
  const PreparedCase& p_;
  ClContext& cl_;
  Transport& transport_;
  std::unique_ptr<SplitRun> split_;
  std::vector<io::BreakRecord> catalogue_;  // rank 0: every break so far (a checkpoint's break log)
};

Snapshot SplitDomain::read(Needs needs) {
  Solver& solver = *solver_;
  SplitRun& split = *split_;
  CohesiveForces* const ce4 = solver.cohesive();
  const bool root = split.root();
  Snapshot s;
  s.step = solver.steps_done(), s.time = solver.time(), s.has = needs;
  if (needs.has(Need::Conditions)) {
    s.conditions = split.conditions(solver);
    if (!s.passed()) return s;
  }
  // A checkpoint's break log is the whole catalogue up to now.
  if (ce4 && (needs.has(Need::Breaks) || needs.has(Need::State))) {
    const auto began = std::chrono::steady_clock::now();
    const auto fresh = split.drain_breaks(*ce4);
    catalogue_.insert(catalogue_.end(), fresh.begin(), fresh.end());
    s.breaks = with_triangles(p_.model, fresh);
    if (cl_.profiling())
      cl_.add_host_time("break catalogue (host wall: count and records read, sort, events file append)",
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
  }
  if (ce4 && needs.has(Need::Catalogue)) {
    catalogue_ = split.catalogue(*ce4);
    s.breaks = with_triangles(p_.model, catalogue_);
  }
  if (needs.has(Need::Energy)) {
    s.energy = solver.energy();
    s.energy_error = solver.balance().error(s.energy);
    s.energy_ratio = solver.balance().ratio(s.energy);
    s.energy_time = solver.energy_time();
  }
  if (needs.has(Need::Positions)) s.positions = split.gather(ItemKind::Node, solver.positions());
  if (needs.has(Need::Forces)) s.forces = split.gather(ItemKind::Node, solver.forces());
  if (needs.has(Need::Velocities)) s.velocities = split.gather(ItemKind::Node, solver.velocities());
  if (needs.has(Need::ContactCounts)) {  // the whole model's, as of the energy read
    s.contact_touching = solver.contact_touching();
    s.contact_candidates = solver.contact_candidates();
    s.contact_rebuilds = solver.contact_rebuilds();
  }
  bool stress_current = false;  // the probes evaluate the stress of this state on every rank
  if (needs.has(Need::Probes)) s.probes = split.probe_values(solver, p_.probes), stress_current = !p_.probes.empty();
  if (needs.has(Need::Stress)) {
    if (!stress_current) solver.enqueue_stress();
    s.stress = split.gather(ItemKind::Triangle, solver.stresses());
  }
  if (needs.has(Need::ContactForces) && solver.has_contact())
    s.contact_forces = split.gather(ItemKind::Node, solver.contact_forces());
  if (ce4 && needs.has(Need::Ce4State)) {
    s.damage = split.gather(ItemKind::Ce4, ce4->damage());
    s.opening = split.gather(ItemKind::Ce4, ce4->opening());
    s.slip = split.gather(ItemKind::Ce4, ce4->slip());
  }
  if (ce4 && (needs.has(Need::Ce4Flags) || needs.has(Need::FragmentLabels))) {
    s.broken = split.gather(ItemKind::Ce4, ce4->broken());
    s.mode = split.gather(ItemKind::Ce4, ce4->mode());
    if (solver.has_extrinsic_stage()) {  // each rank's counter counts its ghosts' insertions too
      const auto inserted = split.gather(ItemKind::Ce4, ce4->inserted_flags());
      if (root) s.inserted_ce4 = static_cast<long>(count_inserted(p_.model, inserted));
    }
  }
  if (ce4 && needs.has(Need::FragmentLabels) && root) s.labels = host_fragment_labels(p_.model, s.broken);
  if (needs.has(Need::State)) {
    const auto began = std::chrono::steady_clock::now();
    io::CheckpointData local;
    StateWriter out(cl_, local);
    solver.save_state(out);
    s.state = split.gather_state(local, catalogue_);  // the whole model's state, as one rank writes it
    s.broken_ce4 = static_cast<long>(catalogue_.size());
    s.state_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  }
  if (needs.has(Need::Masses)) s.masses = split.gather(ItemKind::Node, solver.masses());
  return s;
}

}  // namespace

std::unique_ptr<Domain> make_split_domain(const PreparedCase& p, ClContext& cl, Transport& transport,
                                          PartitionMethod partition, double travel) {
  return std::make_unique<SplitDomain>(p, cl, transport, partition, travel);
}

}  // namespace fdem
