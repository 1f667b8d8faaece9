#include "engine/solver.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <climits>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "base/errors.hpp"
#include "engine/parallel/transport.hpp"

namespace fdem {

namespace {

// make() when wanted, else null (make may use stages that exist only when wanted).
template <class Make>
auto build_if(bool wanted, Make make) -> decltype(make()) {
  return wanted ? make() : nullptr;
}

// The most items of one kind that the account sums (OrderedSums' size).
size_t ordered_items(const Model& model) {
  return std::max({model.num_nodes(), model.num_triangles(), model.loaded_edges.size(), model.ce4.size()});
}

// Activation "fractured" (a candidate mask is given): the two triangles of every CE4 are
// a couple from the start (see ContactDetection); the mask then adds the others as CE4s break.
const std::vector<std::array<int, 2>>& detection_bonds(const Model& model) {
  static const std::vector<std::array<int, 2>> none;
  return model.contact_active.empty() ? none : model.ce4_triangles;
}

// The CE4s as the stage takes them; with contact also each CE4's mesh nodes and the
// bonded fans, for the corner couples contact leaves alone (Model::vertex_bonded).
CohesiveModel cohesive_model(const Model& model) {
  CohesiveModel m{model.ce4, model.ce4_properties, model.fracture, model.thickness, {}, {}, model.ce4_strength_factor, {}, {}, {}, 0.0};
  for (size_t e = 0; e < model.ce4_joint.size(); ++e)
    if (model.ce4_joint[e] >= 0 && model.joint_broken[model.ce4_joint[e]]) {
      m.closed.resize(model.ce4.size(), 0);
      m.closed[e] = 1;
    }
  // [[excavation]]: the excavations of each CE4's two triangles, where either has one.
  if (!model.triangle_excavation.empty()) {
    bool any = false;
    std::vector<std::array<int, 2>> of(model.ce4_triangles.size(), {-1, -1});
    for (size_t e = 0; e < model.ce4_triangles.size(); ++e)
      for (int k = 0; k < 2; ++k) {
        of[e][k] = model.triangle_excavation[model.ce4_triangles[e][k]];
        any = any || of[e][k] >= 0;
      }
    if (any) {
      m.excavation_of = std::move(of);
      for (const auto& x : model.excavations) m.excavation_times.push_back({x.start, x.duration});
    }
  }
  if (model.fluid.enabled) m.fluid_carriers = model.fluid.damaged_segments ? 2 : 1;
  if (model.contact.enabled && !model.node_origin.empty()) {
    m.node_origin = model.node_origin;
    m.vertex_bonded = model.vertex_bonded;
  }
  return m;
}

// [[excavation]] as TriangleForces takes it (empty without).
TriangleExcavation triangle_excavation(const Model& model) {
  TriangleExcavation e;
  e.of = model.triangle_excavation;
  for (const auto& x : model.excavations) e.times.push_back({x.start, x.duration});
  return e;
}

// Whether the step's integration gathers the nodes' forces itself (Integrate::Gather),
// and from what (the sources of NodeGather::enqueue_forces). Measured on the H200
// (docs/performance-notes.md): the fused kernel saves a launch, which models up to a few
// hundred thousand nodes notice, but at 3.2M nodes it took 0.29 ms where the gather and
// the integration took 0.26 together (the integration's local-memory sums limit how many
// work-items hide the gather's scattered reads). CPU devices always take the fused
// kernel: one pass over the nodes instead of two, and no launch to wait for.
constexpr size_t kFusedGatherNodes = 262144;
std::optional<Integrate::Gather> step_gather(const ClContext& cl, size_t nodes, CohesiveForces* cohesive,
                                             ContactForces* contact, FluidFlow* fluid) {
  if (cl.info().is_gpu && nodes > kFusedGatherNodes) return std::nullopt;
  return Integrate::Gather{cohesive ? &cohesive->slots() : nullptr, contact ? contact->force_scale() : 0.0,
                           fluid ? &fluid->slots() : nullptr, fluid ? &fluid->loaded_nodes() : nullptr};
}

}  // namespace

// The boundary loads ride in the triangle stage's launch (BoundaryLoads::bind_tail): one
// launch a step less wherever edges are loaded. FDEM_BOUNDARY_FUSED=0 launches them on
// their own, for the test that compares the two (tests/test_contact_lanes.cpp).
static bool boundary_fused() {
  const char* env = std::getenv("FDEM_BOUNDARY_FUSED");
  if (!env || !*env) return true;
  if (std::string(env) != "0" && std::string(env) != "1")
    throw DeviceError(std::string("FDEM_BOUNDARY_FUSED=") + env + " is neither 0 nor 1");
  return *env == '1';
}

std::unique_ptr<ContactDetection> Solver::build_detection(bool wanted, ClContext& cl, DeviceArrays& arrays,
                                                          const Model& model) {
  if (!wanted) return nullptr;
  auto detection = std::make_unique<ContactDetection>(cl, arrays, model.contact.skin, 0, detection_bonds(model),
                                                      model.triangle_owned, model.contact.list_ahead);
  if (!model.contact_active.empty()) detection->set_active(model.contact_active);
  return detection;
}

Solver::Parts Solver::parts(const Model& model, bool account) {
  Parts p;
  p.ce4 = !model.ce4.empty();
  p.contact = model.contact.enabled;
  p.skin = p.contact && model.contact.rebuild_skin;
  // Without a skin detection runs every step and nobody reads the join flags in the ring.
  p.activation = p.contact && p.ce4 && !model.contact_active.empty();
  // Nobody reads the ring's join flag when couples are listed ahead of joins, so the CE4
  // stage can mark the candidates itself; a split run's ghost CE4s break on their owners'
  // ranks, so there every rank keeps the activation's launch.
  p.activation_on_break = p.activation && p.skin && model.contact.list_ahead && model.ce4_owned.empty();
  if (const char* env = std::getenv("FDEM_ACTIVATE_ON_BREAK"); env && *env) {
    if (std::string(env) != "0" && std::string(env) != "1")
      throw DeviceError(std::string("FDEM_ACTIVATE_ON_BREAK=") + env + " is neither 0 nor 1");
    if (*env == '0') p.activation_on_break = false;
  }
  p.viscous = account && std::any_of(model.materials.begin(), model.materials.end(),
                                     [](const MaterialConstants& m) { return m.viscosity != 0; });
  p.prescribed = model.groups.size() > 1;
  p.account_work = Integrate::accounts_work(p.prescribed, model.local_damping, account);
  p.fluid = p.ce4 && model.fluid.enabled;
  p.extrinsic = p.ce4 && has_extrinsic(model);
  return p;
}

MemoryPlan Solver::plan(const Model& model, size_t group_size, bool account) {
  const Parts p = parts(model, account);
  const size_t nodes = model.num_nodes(), triangles = model.num_triangles();
  MemoryPlan plan = DeviceArrays::plan(model);
  if (p.ce4)
    plan.add(CohesiveForces::plan(model.ce4.size(), p.contact && !model.node_origin.empty() ? model.vertex_bonded.size() : 0,
                                  cohesive_property_sets(cohesive_model(model)), model.in_situ.enabled, p.extrinsic,
                                  cohesive_model(model).excavation_of.empty() ? 0 : model.excavations.size(), p.fluid,
                                  nodes));
  if (p.extrinsic) plan.add(Extrinsic::plan(model));
  if (p.ce4) plan.add(FragmentLabels::plan(triangles, nodes, model.ce4_triangles.size()));
  if (p.contact) {
    plan.add(MonitorRing::plan());
    plan.add(ContactDetection::plan(triangles, group_size, 0, !detection_bonds(model).empty(), !model.triangle_owned.empty()));
  }
  if (p.skin) plan.add(ContactSkin::plan(nodes, !model.node_owned.empty()));
  if (p.activation) plan.add(ContactActivation::plan(model.ce4_triangles.size(), !model.ce4_owned.empty()));
  // The detection's mask and couple list (shared keys).
  if (p.contact) plan.add(ContactForces::plan(model, group_size, false, p.skin, true));
  if (p.fluid) plan.add(FluidFlow::plan(model));
  plan.add(TriangleForces::plan(triangles, group_size, p.viscous, model.in_situ.enabled, model.excavations.size(),
                                !model.node_owned.empty()));
  plan.add(BoundaryLoads::plan(model.loaded_edges.size(), group_size));
  // A split rank (with contact: its node ownership; engine/parallel/partition.cpp) keeps the
  // energy rows' per-node values for energy()'s gather (set_scope → keep_energy_rows).
  plan.add(Integrate::plan(nodes, group_size, p.account_work, !model.node_owned.empty(),
                           Integrate::work_rows(model.node_group, model.groups.size(), model.local_damping).rows));
  plan.add(LumpedMass::plan(nodes, p.ce4));
  plan.add(OrderedSums::plan(ordered_items(model)));
  return plan;
}

size_t Solver::expected_couples(const Model& model) {
  if (!model.contact.enabled) return 0;
  // Listed ahead of joins ("fractured" with a skin), a list holds every triangle's couples.
  if (model.contact_active.empty() || model.contact.list_ahead) return 7 * model.num_triangles();
  const size_t active = static_cast<size_t>(std::count_if(model.contact_active.begin(), model.contact_active.end(),
                                                          [](uint32_t a) { return a != 0; }));
  return 7 * active + model.ce4.size();
}

size_t Solver::expected_touching(const Model& model) {
  if (!model.contact.enabled) return 0;
  return expected_couples(model) / 32;
}

size_t Solver::bytes_needed(const Model& model, size_t group_size, bool account) {
  size_t bytes = plan(model, group_size, account).total();
  const size_t couples = expected_couples(model), first = ContactForces::first_capacity(model.num_triangles());
  if (couples > first)
    bytes += ContactForces::couple_arrays(ContactForces::grown(couples), group_size, !model.ce4_triangles.empty()).resident() -
             ContactForces::couple_arrays(first, group_size, !model.ce4_triangles.empty()).resident();
  // The history pool: with a skin it grows with the touching couples, else it has a row
  // per couple of the list.
  const size_t triangles = model.num_triangles();
  const bool skin = model.contact.enabled && model.contact.rebuild_skin;
  const size_t pool_first = skin ? ContactForces::pool_first(triangles) : first;
  const size_t pool_then = skin ? ContactForces::pool_grown(expected_touching(model), triangles)
                                : (couples > first ? ContactForces::grown(couples) : first);
  if (model.contact.enabled && pool_then > pool_first)
    bytes += ContactForces::pool_arrays(pool_then).resident() - ContactForces::pool_arrays(pool_first).resident();
  const size_t first_keys = ContactDetection::first_capacity(model.num_triangles());
  if (couples > first_keys)
    bytes += ContactDetection::couple_list(ContactDetection::grown(couples)).resident() -
             ContactDetection::couple_list(first_keys).resident();
  return bytes;
}

Solver::Parts Solver::fitting_parts(const ClContext& cl, const Model& model, bool account) {
  const size_t needed = bytes_needed(model, cl.group_size(), account);
  if (needed > cl.info().global_memory)
    throw DeviceError("too little device memory: the model needs " + std::to_string(needed >> 20) +
                      " MiB, device " + cl.info().device_name + " has " +
                      std::to_string(cl.info().global_memory >> 20) + " MiB");
  return parts(model, account);
}

Solver::Solver(ClContext& cl, const Model& model, double dt, bool account)
    : cl_(cl),
      dt_(dt),
      parts_(fitting_parts(cl, model, account)),
      arrays_(cl, model),
      cohesive_(build_if(parts_.ce4,
                         [&] {
                           CohesiveModel m = cohesive_model(model);
                           m.dt = dt;
                           m.activate_on_break = parts_.activation_on_break;
                           return std::make_unique<CohesiveForces>(cl, m, arrays_.position, arrays_.velocity,
                                                                   DeviceArrays::reference_positions(model),
                                                                   in_situ_ce4_gaps(model));
                         })),
      fragments_(build_if(parts_.ce4,
                          [&] {
                            return std::make_unique<FragmentLabels>(cl, model.num_triangles(), model.num_nodes(),
                                                                    arrays_.tri_nodes, model.ce4_triangles,
                                                                    &cohesive_->status());
                          })),
      ring_(build_if(parts_.contact, [&] { return std::make_unique<MonitorRing>(cl); })),
      detection_(build_detection(parts_.contact, cl, arrays_, model)),
      skin_(build_if(parts_.skin,
                     [&] { return std::make_unique<ContactSkin>(cl, arrays_, *ring_, model.contact.skin, dt, model.node_owned); })),
      activation_(build_if(parts_.activation,
                           [&] {
                             return std::make_unique<ContactActivation>(cl, model.ce4_triangles.size(),
                                                                        fragments_->ce4_triangles(), cohesive_->status(),
                                                                        detection_->active_mask(), *ring_,
                                                                        model.ce4_owned);
                           })),
      contact_(build_if(parts_.contact,
                        [&] {
                          return std::make_unique<ContactForces>(cl, arrays_, model, &detection_->active_mask(),
                                                                 cohesive_ ? &cohesive_->status() : nullptr,
                                                                 cohesive_ ? cohesive_->mesh_node_state() : nullptr,
                                                                 cohesive_ ? cohesive_->node_origin() : nullptr,
                                                                 parts_.skin ? ring_.get() : nullptr, true,
                                                                 cohesive_ ? &cohesive_->status_step() : nullptr);
                        })),
      fluid_(build_if(parts_.fluid,
                      [&] { return std::make_unique<FluidFlow>(cl, model, arrays_.position, cohesive_->status(),
                                                               cohesive_->gauss_state(), dt, cohesive_->fluid_carriers()); })),
      boundary_loads_(cl, arrays_, model.thickness, dt, model.in_situ.enabled,
                      fluid_ && model.fluid.gas ? &fluid_->gas_hole() : nullptr),
      triangle_forces_(cl, arrays_, model.thickness, dt, parts_.viscous, in_situ_triangle_stress(model),
                       triangle_excavation(model), boundary_fused() ? &boundary_loads_ : nullptr,
                       fluid_ && fluid_->headed() ? fluid_.get() : nullptr),
      gather_(cl, arrays_, cohesive_ ? &cohesive_->slots() : nullptr, contact_ ? contact_->force_scale() : 0.0,
              fluid_ ? &fluid_->slots() : nullptr, fluid_ ? &fluid_->loaded_nodes() : nullptr),
      integrate_(cl, arrays_, model.gravity, model.local_damping, dt, parts_.prescribed, account, skin_.get(),
                 step_gather(cl, model.num_nodes(), cohesive_.get(), contact_.get(), fluid_.get())),
      extrinsic_(build_if(parts_.extrinsic, [&] { return std::make_unique<Extrinsic>(cl, arrays_, model, *cohesive_); })),
      ordered_(cl, ordered_items(model)),
      row_reads_(cl),
      ce4_count_(model.ce4.size()) {
  list_ahead_ = model.contact.list_ahead;
  if (parts_.activation_on_break) cohesive_->join_on_break(fragments_->ce4_triangles(), detection_->active_mask());
  // `skin = "auto"`: picked at each detection. A split run keeps its first skin: its
  // contact ghosts reach as far as that skin allows (engine/scale_out.cpp).
  if (skin_ && model.contact.skin_auto && model.node_owned.empty())
    skin_->adapt(mean_edge_length(model), model.num_triangles());
  if (contact_) {
    double reach = 0, longest = 0;
    for (size_t i = 0; i < model.num_nodes(); ++i) reach = std::max({reach, std::fabs(model.x[i]), std::fabs(model.y[i])});
    for (const auto& tri : model.triangles)
      for (int k = 0; k < 3; ++k)
        longest = std::max(longest, std::hypot(model.x[tri[(k + 1) % 3]] - model.x[tri[k]], model.y[tri[(k + 1) % 3]] - model.y[tri[k]]));
    if (model.whole_longest_edge > 0) longest = model.whole_longest_edge, reach = model.whole_reach;  // a split run
    contact_round_off_ = model.contact.max_normal_penalty * model.thickness * std::numeric_limits<real>::epsilon() * reach *
                         3 * longest;
  }
  strain_round_off_ = strain_round_off(model);
  LumpedMass(cl, arrays_, model, dt).enqueue(gather_);
  cl.finish();
}

// The strain energy is computed from current positions, each known to ε |x|: a body at
// rest holds ½ C (ε |x| / h)² A t of round-off strain energy per triangle, which must not
// count as an unbalanced account when every energy is that small (a block at rest with
// no load gave energy_error 0.23 and a stop). Bound: positions off by ε |x|max at each
// corner, a strain error of 4 ε |x|max / h (h: the triangle's shortest height). With an
// in-situ stress S₀ the energy has the term S₀:E, linear in that error: max |S₀| × it × A t
// (without it a column at rest in its in-situ state showed energy_error 0.06 of noise).
double Solver::strain_round_off(const Model& model) {
  double total = 0;
  {
    double reach = 0;
    for (size_t i = 0; i < model.num_nodes(); ++i) reach = std::max({reach, std::fabs(model.x[i]), std::fabs(model.y[i])});
    const double eps = std::numeric_limits<real>::epsilon();
    for (size_t t = 0; t < model.num_triangles(); ++t) {
      const auto& v = model.triangles[t];
      const double ax = model.x[v[1]] - model.x[v[0]], ay = model.y[v[1]] - model.y[v[0]];
      const double bx = model.x[v[2]] - model.x[v[0]], by = model.y[v[2]] - model.y[v[0]];
      const double area = 0.5 * std::fabs(ax * by - ay * bx);
      double longest = 0;
      for (int k = 0; k < 3; ++k)
        longest = std::max(longest, std::hypot(model.x[v[(k + 1) % 3]] - model.x[v[k]], model.y[v[(k + 1) % 3]] - model.y[v[k]]));
      if (area <= 0 || longest <= 0) continue;
      const double height = 2 * area / longest, strain = 4 * eps * reach / height;
      total += 0.5 * model.materials[model.triangle_material[t]].wave_modulus * strain * strain * area * model.thickness;
      // An in-situ stress S₀ adds S₀:E, linear in that strain error (docs/energy-notes.md).
      if (model.in_situ.enabled) {
        const auto s = model.in_situ.at((model.y[v[0]] + model.y[v[1]] + model.y[v[2]]) / 3.0);
        total += std::max({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])}) * strain * area * model.thickness;
      }
    }
  }
  return total;
}

void Solver::step(bool energy_row) {
  step_forces(energy_row);
  if (extrinsic_ && after_integration_) after_integration_();
  step_tie();
  if (extrinsic_ && after_tie_) after_tie_();
  step_finish();
}

void Solver::step_forces(bool energy_row) {
  const double t = time();
  // The first step always evaluates the account: its stored energy is the balance's start.
  energy_row = energy_row || steps_ == 0;
  if (energy_row) energy_row_step_ = steps_;
  // The step, stage by stage. Each stage writes its own slots; the gather sums them.
  if (contact_) {
    contact_->begin_step(steps_);
    // Detection every step, or with a skin once some node may have moved more than half
    // of it since the last detection (no couple can have appeared before that), or when
    // triangles next to newly broken CE4s joined the candidates ("fractured").
    if (activation_ && (!parts_.activation_on_break || steps_ == activation_catch_up_)) activation_->enqueue(steps_);
    ContactSkin::Due due =
        !skin_ || rebuilds_ == 0 || detect_after_load_ ? ContactSkin::Due::Moved : skin_->rebuild_due(steps_);
    detect_after_load_ = false;
    // With couples listed ahead of joins ("fractured" with a skin) a join needs no new
    // list: its couples are in it, and act from the step the join happens.
    if (due == ContactSkin::Due::Joined && list_ahead_) due = ContactSkin::Due::Nothing;
    if (due != ContactSkin::Due::Nothing) {
      const auto start = std::chrono::steady_clock::now();
      if (before_detection_) before_detection_();
      contact_->carry_before_detection();  // the detection rewrites the list the stage reads
      // An adaptive skin picks this detection's margin (ContactSkin::choose).
      if (skin_ && skin_->adaptive()) detection_->set_skin(skin_->choose(contact_->couples()));
      const size_t count = detection_->run();
      detection_->set_covered_stamp(ContactActivation::join_stamp(steps_));
      if (cl_.profiling())
        cl_.add_host_time("contact detection (host wall, incl. count read)",
                          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      contact_->enqueue(detection_->couple_keys(), count, true, dt_, energy_row, steps_);
      if (skin_) {
        skin_->mark();
        skin_->joins_covered(steps_);
      }
      ++rebuilds_;
    } else {
      if (skin_) contact_->ensure_pool(skin_->pool_rows_seen(), skin_->pool_rows_per_step());
      contact_->enqueue(detection_->couple_keys(), contact_->couples(), false, dt_, energy_row, steps_);
    }
    if (contact_sent_) contact_sent_();
  }
  boundary_loads_.enqueue(t, static_cast<int>(steps_));
  // With the liquid's step in the triangle stage's launch (FluidFlow::headed) that launch
  // comes after the CE4s and the fluid's list rescans, whose results the step reads; the
  // triangles read nothing the CE4s write, so the order moves no bit.
  const bool fluid_headed = fluid_ && fluid_->headed();
  if (!fluid_headed) triangle_forces_.enqueue(static_cast<int>(steps_), energy_row);
  if (cohesive_) cohesive_->enqueue(t, steps_);
  if (fluid_) fluid_->enqueue(t, steps_);  // after the CE4s: it reads their status of this step
  if (fluid_headed) triangle_forces_.enqueue(static_cast<int>(steps_), energy_row);
  if (contact_received_) contact_received_();
  // Small models: the integration gathers the nodes' forces itself (step_gather).
  if (!integrate_.gathers()) gather_.enqueue_forces();
  integrate_.enqueue(t + dt_, static_cast<int>(steps_), energy_row);
}

// Extrinsic CE4s: tied copies moved as one, then this step's insertions
// (cl_kernels/extrinsic.cl). A split run's ghost copies take their owners' integrated
// state before the tie, and every ghost its owner's tied one before the insertions read
// them (set_extrinsic_hooks).
void Solver::step_tie() {
  if (extrinsic_) extrinsic_->enqueue_tie();
}

void Solver::step_finish() {
  if (extrinsic_) extrinsic_->enqueue_insert();
  if (skin_) skin_->measured(steps_ + 1);
  ++steps_;
  if (!balance_.started()) balance_.start(energy());
}

EnergyTotals Solver::energy() {
  if (cl_.profiling()) cl_.finish();  // time the account alone, not the steps queued before it
  const auto start = std::chrono::steady_clock::now();
  row_reads_.begin();
  const EnergyTotals e = queue_energy()();
  if (cl_.profiling())
    cl_.add_host_time("energy account (host wall: per-item reads and ordered sums, at history rows)",
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return e;
}

std::function<EnergyTotals()> Solver::queue_energy() {
  // Every term is a sum of per-item values in global item order by one rule (OrderedSums
  // on one rank, SplitSums over the ranks), so a split run gives the bits of one rank.
  SplitSums* split = split_sums_.get();
  OrderedSums& device = ordered_;
  RowReads& reads = row_reads_;
  const ItemSums sums = [split, &device, &reads](ClContext& cl, const compute::buffer& values, size_t count, int stride,
                                                 int first, int width, ItemKind kind) {
    if (!split) return device.queue(values, count, stride, first, width, reads);
    return sums_now(split->sums(cl, values, count, stride, first, width, kind));
  };
  std::vector<EnergyPart> parts;
  parts.push_back(integrate_.queue_energy(sums, split ? nullptr : &reads));
  parts.push_back(triangle_forces_.queue_energy(sums, split ? nullptr : &reads));
  parts.push_back(boundary_loads_.queue_energy(sums));
  if (cohesive_) {
    // (fracture dissipation, stored energy): columns 1 and 2 of each CE4's energy row.
    PendingSums pending = sums(cl_, cohesive_->energy_rows(), ce4_count_, 3, 1, 2, ItemKind::Ce4);
    parts.push_back([pending](EnergyTotals& e) {
      const auto sum = pending();
      e.fracture += sum[0];
      e.cohesive_stored += sum[1];
    });
    // [[excavation]]: what the ramped CE4s carried out (column 1 of their excavation rows).
    if (cohesive_->excavating()) {
      PendingSums carried = sums(cl_, cohesive_->excavation_rows(), ce4_count_, 2, 1, 1, ItemKind::Ce4);
      parts.push_back([carried](EnergyTotals& e) { e.excavated += carried()[0]; });
    }
  }
  if (fluid_) parts.push_back(fluid_->queue_energy(sums));
  if (contact_ && scope_) {
    EnergyTotals contact;
    add_split_contact_energy(contact);  // collective: every rank now
    parts.push_back([contact](EnergyTotals& e) {
      e.resolution += contact.resolution;
      e.contact_stored += contact.contact_stored;
      e.friction += contact.friction;
      e.contact_damping += contact.contact_damping;
    });
  } else if (contact_) {
    auto terms = contact_->queue_row(reads);
    const double round_off = contact_round_off_;
    parts.push_back([terms, round_off](EnergyTotals& e) {
      const ContactForces::RowTerms t = terms();
      // Each touching couple's potential is P_n t times areas whose vertices are known to
      // ε |x|: an error of about P_n t ε |x| (perimeter); independent errors add like √N.
      e.resolution += std::sqrt(double(t.touching)) * round_off;
      e.contact_stored += t.stored;
      e.friction += t.friction;
      e.contact_damping += t.damping;
    });
  }
  // Each step's forces carry that round-off too, and their work adds up step after step.
  const double resolution = strain_round_off_ * static_cast<double>(std::max(1L, steps_));
  return [parts, resolution] {
    EnergyTotals e;
    e.resolution = resolution;
    for (const auto& part : parts) part(e);
    return e;
  };
}

void Solver::set_scope(const ItemScope* scope) {
  scope_ = scope;
  split_sums_ = scope ? std::make_unique<SplitSums>(*scope) : nullptr;
  if (scope_) integrate_.keep_energy_rows();  // the split sums read the per-node values
  if (scope_) triangle_forces_.keep_energy_rows();  // and the per-triangle ones
}

void Solver::add_split_contact_energy(EnergyTotals& e) {
  // Every rank lists the couples whose lower triangle it owns, each couple of the whole
  // model exactly once, and local order is global order, so the whole list sorted by
  // global key is one rank's. The fixed-point words and the counts are integers: their
  // sums over the ranks are one rank's. The stored energy one rank sums per work-group of
  // its list (tree_group_sums): only the nonzero values and their places in the whole
  // list matter. A value's place is the number of keys below its key over all ranks'
  // lists: rank 0 gathers the nonzero (key, value) pairs (a few percent of the list),
  // every rank counts its keys below each key, rank 0 adds the counts.
  Transport& transport = *scope_->transport;
  if (split_keys_generation_ != contact_->list_generation()) {
    const auto& tri_global = scope_->global[static_cast<int>(ItemKind::Triangle)];
    split_keys_ = contact_->list_keys();
    for (auto& k : split_keys_) k = (cl_ulong(tri_global[k >> 32]) << 32) | cl_ulong(tri_global[k & 0xffffffffu]);
    if (!std::is_sorted(split_keys_.begin(), split_keys_.end()))
      throw std::logic_error("split contact energy: the list is not in global order");
    split_keys_generation_ = contact_->list_generation();
  }
  const auto stored = contact_->stored_couples();
  std::vector<cl_ulong> keys(stored.index.size());
  for (size_t n = 0; n < keys.size(); ++n) keys[n] = split_keys_[stored.index[n]];
  const auto words = contact_->energy_account();
  std::vector<cl_long> mine(words.begin(), words.end());
  mine.push_back(static_cast<cl_long>(stored.touching));
  mine.push_back(static_cast<cl_long>(contact_->couples()));
  const auto all_words = transport.gather(to_bytes(mine));
  const auto all_keys = transport.gather(to_bytes(keys));
  const auto all_values = transport.gather(to_bytes(stored.value));
  // Every rank's nonzero keys, in rank order: sorted within each rank's run.
  std::vector<cl_ulong> queries;
  for (const auto& b : all_keys) {
    const auto k = from_bytes<cl_ulong>(b);
    queries.insert(queries.end(), k.begin(), k.end());
  }
  queries = from_bytes<cl_ulong>(transport.broadcast(to_bytes(queries)));
  const auto all_below = transport.gather(to_bytes(count_below(split_keys_, queries)));
  std::vector<double> totals;  // friction, damping, touching, candidates, stored (rank 0)
  if (transport.rank() == 0) {
    std::vector<cl_long> sum(mine.size(), 0);
    for (const auto& b : all_words) {
      const auto w = from_bytes<cl_long>(b);
      for (size_t k = 0; k < sum.size(); ++k) sum[k] += w[k];
    }
    std::vector<uint64_t> place(queries.size(), 0);
    for (const auto& b : all_below) {
      const auto below = from_bytes<uint64_t>(b);
      for (size_t q = 0; q < place.size(); ++q) place[q] += below[q];
    }
    // (place, value), each rank's run ascending: merged run by run into one ascending list.
    std::vector<std::pair<uint64_t, real>> nonzero;
    nonzero.reserve(queries.size());
    for (const auto& b : all_values) {
      const auto v = from_bytes<real>(b);
      const auto middle = static_cast<std::ptrdiff_t>(nonzero.size());
      for (const real x : v) nonzero.emplace_back(place[nonzero.size()], x);
      std::inplace_merge(nonzero.begin(), nonzero.begin() + middle, nonzero.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
    }
    const auto candidates = static_cast<uint64_t>(sum[words.size() + 1]);
    for (size_t n = 0; n < nonzero.size(); ++n)
      if (nonzero[n].first >= candidates || (n > 0 && nonzero[n].first == nonzero[n - 1].first))
        throw std::logic_error("split contact energy: a couple on two ranks, or off the list");
    const double scale = contact_->energy_scale();
    totals = {static_cast<double>(sum[layout::ENERGY_FRICTION]) / scale, static_cast<double>(sum[layout::ENERGY_DAMPING]) / scale,
              static_cast<double>(sum[words.size()]), static_cast<double>(sum[words.size() + 1]),
              tree_group_sums(nonzero, cl_.group_size())};
  }
  totals = from_bytes<double>(transport.broadcast(to_bytes(totals)));
  split_touching_ = static_cast<size_t>(totals[2]);
  split_candidates_ = static_cast<size_t>(totals[3]);
  e.resolution += std::sqrt(totals[2]) * contact_round_off_;
  e.contact_stored += totals[4];
  e.friction += totals[0];
  e.contact_damping += totals[1];
}

double Solver::time_detections(int repeats) {
  if (!detection_ || repeats < 1) return 0;
  cl_.finish();
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < repeats; ++r) {
    detection_->run();
    cl_.finish();
  }
  return 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repeats;
}

void Solver::save_state(StateWriter& out) {
  cl_.finish();
  out.integer("step", steps_);
  out.integer("contact_rebuilds", rebuilds_);
  const cl_long extensions = extensions_;
  out.host<cl_long>("contact_extensions", &extensions, 1);
  out.integer("energy_row_step", energy_row_step_);
  const auto b = balance_.state();
  out.number("balance_initial_stored", b[0]);
  out.number("balance_peak_kinetic", b[1]);
  out.buffer<real>("position", arrays_.position, arrays_.num_nodes, 2);
  out.buffer<real>("velocity", arrays_.velocity, arrays_.num_nodes, 2);
  // The loads' last forces: the next step's work uses them (trapezoid rule).
  out.buffer<real>("edge_force", arrays_.edge_force, 2 * arrays_.num_loaded_edges, 2);
  integrate_.save_state(out);
  triangle_forces_.save_state(out);
  boundary_loads_.save_state(out);
  if (cohesive_) cohesive_->save_state(out);
  if (fluid_) fluid_->save_state(out);
  if (contact_) {
    contact_->save_state(out);
    detection_->save_state(out);
    if (skin_) skin_->save_state(out);
  }
  cl_.finish();
}

void Solver::load_state(StateReader& in) {
  steps_ = static_cast<long>(in.integer("step"));
  activation_catch_up_ = steps_;  // CE4s that broke before the checkpoint (a no-op for this build's own)
  rebuilds_ = static_cast<long>(in.integer("contact_rebuilds"));
  cl_long extensions = 0;
  if (in.has("contact_extensions")) in.host<cl_long>("contact_extensions", &extensions, 1);
  extensions_ = static_cast<long>(extensions);
  energy_row_step_ = static_cast<long>(in.integer("energy_row_step"));
  balance_.restore({in.number("balance_initial_stored"), in.number("balance_peak_kinetic")});
  in.buffer<real>("position", arrays_.position, arrays_.num_nodes, 2);
  in.buffer<real>("velocity", arrays_.velocity, arrays_.num_nodes, 2);
  in.buffer<real>("edge_force", arrays_.edge_force, 2 * arrays_.num_loaded_edges, 2);
  integrate_.load_state(in);
  triangle_forces_.load_state(in);
  boundary_loads_.load_state(in);
  if (cohesive_) cohesive_->load_state(in);
  if (extrinsic_) extrinsic_->mark_inserted();
  if (fluid_) fluid_->load_state(in);
  if (contact_) {
    contact_->load_state(in);
    detection_->load_state(in);
    // A checkpoint of a list that held only the couples of active triangles (before
    // couples were listed ahead of joins, 2026-12-03): the next step lists them all.
    detect_after_load_ = list_ahead_ && !in.has_number("skin_current");
    if (skin_) {
      skin_->load_state(in);
      // The list and the last detection's grid as the run had them, so that a join is met
      // by the same extension as in the run that wrote the checkpoint.
      if (detection_->restore_list(in)) contact_->share_keys(detection_->couple_keys());
      detection_->rebuild_grid(skin_->position_at_build());
    }
  }
  labels_step_ = -1;
  labels_broken_ = -1;
  cl_.finish();
  save_checkpoint();
  cl_.finish();
}

std::vector<real2> Solver::contact_forces() {
  std::vector<real2> out(arrays_.num_nodes);
  if (!contact_) return out;
  const auto acc = download<cl_long>(cl_, arrays_.contact_acc, 2 * arrays_.num_nodes);
  const double unit = 1.0 / contact_->force_scale();
  for (size_t i = 0; i < out.size(); ++i) out[i] = {real(acc[2 * i] * unit), real(acc[2 * i + 1] * unit)};
  return out;
}

const std::vector<int>& Solver::fragment_labels(long broken) {
  if (fragments_ && labels_step_ >= 0 && broken >= 0 && broken == labels_broken_) labels_step_ = steps_;
  if (fragments_ && labels_step_ != steps_) {
    if (cl_.profiling()) cl_.finish();  // time the labelling alone, not the steps queued before it
    const auto start = std::chrono::steady_clock::now();
    labels_ = fragments_->labels();
    labels_step_ = steps_;
    labels_broken_ = broken;
    if (cl_.profiling()) {
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      cl_.add_host_time("fragment labelling (host wall, incl. flag reads and labels read back)", seconds);
      // Rounds: the launches of fragment_shortcut in the kernel profile.
    }
  }
  return labels_;
}

void Solver::enqueue_stress() { triangle_forces_.enqueue_stress(static_cast<int>(steps_)); }

std::vector<real2> Solver::positions() { return download<real2>(cl_, arrays_.position, arrays_.num_nodes); }
std::vector<real2> Solver::velocities() { return download<real2>(cl_, arrays_.velocity, arrays_.num_nodes); }
std::vector<real2> Solver::forces() { return download<real2>(cl_, arrays_.node_force, arrays_.num_nodes); }
std::vector<real2> Solver::masses() {
  if (arrays_.mass_scaling) return download<real2>(cl_, arrays_.node_mass, arrays_.num_nodes);
  std::vector<real2> out;  // without mass scaling the device holds the mass once (LumpedMass)
  for (const real m : download<real>(cl_, arrays_.node_mass, arrays_.num_nodes)) out.push_back(real2{m, m});
  return out;
}
std::vector<real4> Solver::stresses() {
  if (arrays_.stress.get() == nullptr) throw DeviceError("Solver::stresses: no stress evaluated since the last output");
  return download<real4>(cl_, arrays_.stress, arrays_.num_triangles);
}

std::function<Conditions()> Solver::queue_conditions() {
  auto pool = contact_ ? contact_->queue_pool_state(row_reads_) : std::function<std::vector<cl_uint>()>();
  auto words = row_reads_.read<int>(arrays_.conditions, layout::CONDITION_WORDS);
  ContactForces* contact = contact_.get();
  FluidFlow* fluid = fluid_.get();
  auto wide = fluid ? fluid->queue_too_wide(row_reads_) : std::function<std::vector<cl_int>()>();
  return [pool, words, contact, fluid, wide] {
    const auto w = words();
    if (contact) contact->check_pool(pool().data());
    if (fluid) fluid->check_too_wide(wide());
    auto value = [](int v) { return v == INT_MAX ? -1 : v; };
    return Conditions{value(w[layout::COND_BAD_NODE]), value(w[layout::COND_BAD_NODE_STEP]),
                      value(w[layout::COND_INVERTED_TRI]), value(w[layout::COND_INVERTED_STEP])};
  };
}

std::function<std::vector<real2>()> Solver::queue_positions() {
  return row_reads_.read<real2>(arrays_.position, arrays_.num_nodes);
}
std::function<std::vector<real2>()> Solver::queue_forces() {
  return row_reads_.read<real2>(arrays_.node_force, arrays_.num_nodes);
}

Conditions Solver::conditions() {
  // The pool's state is read without waiting; the conditions' read waits, and the queue
  // is in order, so both have landed after it: one wait for the device instead of two.
  std::array<cl_uint, 2> pool{};
  if (contact_) contact_->read_pool_state(pool.data());
  const auto words = download<int>(cl_, arrays_.conditions, layout::CONDITION_WORDS);
  if (contact_) contact_->check_pool(pool.data());
  if (fluid_) {
    const auto wide = fluid_->too_wide();
    if (wide.first >= 0) fluid_->check_too_wide({wide.first, wide.second});
  }
  auto value = [](int w) { return w == INT_MAX ? -1 : w; };
  return {value(words[layout::COND_BAD_NODE]), value(words[layout::COND_BAD_NODE_STEP]),
          value(words[layout::COND_INVERTED_TRI]), value(words[layout::COND_INVERTED_STEP])};
}

// The copies live on the host (32 B a node read at each passed check, every 200 steps and
// at each output: the checks have just waited for the queue anyway); on the device they
// took two node arrays, 95 B/TRI3 of the bench model.
void Solver::save_checkpoint() {
  const size_t n = arrays_.num_nodes, bytes = n * sizeof(real2);
  saved_position_.resize(n);
  saved_velocity_.resize(n);
  // One wait: the first read is asynchronous, the in-order queue lands it before the second.
  cl_.queue().enqueue_read_buffer_async(arrays_.position, 0, bytes, saved_position_.data());
  cl_.queue().enqueue_read_buffer(arrays_.velocity, 0, bytes, saved_velocity_.data());
  checkpoint_step_ = steps_;
}

void Solver::restore_checkpoint() {
  if (checkpoint_step_ < 0) return;
  const size_t bytes = arrays_.num_nodes * sizeof(real2);
  cl_.queue().enqueue_write_buffer(arrays_.position, 0, bytes, saved_position_.data());
  cl_.queue().enqueue_write_buffer(arrays_.velocity, 0, bytes, saved_velocity_.data());
  steps_ = checkpoint_step_;
  labels_step_ = -1;
  labels_broken_ = -1;
  cl_.finish();
}

}  // namespace fdem
