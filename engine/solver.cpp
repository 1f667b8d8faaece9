#include "engine/solver.hpp"

#include <chrono>
#include <climits>

#include "engine/errors.hpp"

namespace fdem {

Solver::Solver(ClContext& cl, const Model& model, double dt)
    : cl_(cl),
      dt_(dt),
      arrays_(cl, model),
      triangle_forces_(cl, arrays_, model.thickness),
      gather_(cl, arrays_),
      boundary_loads_(cl, arrays_, model.thickness),
      integrate_(cl, arrays_, model.gravity, model.local_damping, dt) {
  if (model.contact.enabled) {
    detection_ = std::make_unique<ContactDetection>(cl, arrays_, model.contact.skin);
    contact_ = std::make_unique<ContactForces>(cl, arrays_, model);
    gather_.add_contact(contact_->force_scale());
    if (model.contact.rebuild_skin) {
      skin_ = std::make_unique<ContactSkin>(cl, arrays_);
      skin_distance_ = model.contact.skin;
    }
  }
  LumpedMass mass(cl, arrays_, model.thickness);
  mass.enqueue(gather_, model.mass_scaling, dt);
  saved_position_ = cl.allocate(arrays_.num_nodes * sizeof(real2), "saved_position");
  saved_velocity_ = cl.allocate(arrays_.num_nodes * sizeof(real2), "saved_velocity");
  cl.finish();
}

void Solver::step() {
  const double t = time();
  // The step, stage by stage. Each stage writes its own slots; the gather sums them.
  if (contact_) {
    contact_->enqueue_clear();
    // Detection every step, or with a skin only once some node has moved more than
    // half of it since the last detection (no couple can have appeared before that).
    const bool rebuild = !skin_ || rebuilds_ == 0 || skin_->largest_move() > 0.5 * skin_distance_;
    if (rebuild) {
      const auto start = std::chrono::steady_clock::now();
      const size_t count = detection_->run();
      if (cl_.profiling())
        cl_.add_host_time("contact detection (host wall, incl. sorts and count read)",
                          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      contact_->enqueue(detection_->couple_keys(), count, true, dt_);
      if (skin_) skin_->mark();
      ++rebuilds_;
    } else {
      contact_->enqueue(detection_->couple_keys(), contact_->couples(), false, dt_);
    }
  }
  boundary_loads_.enqueue(t);
  triangle_forces_.enqueue(static_cast<int>(steps_), false);
  gather_.enqueue_forces();
  integrate_.enqueue(t + dt_, static_cast<int>(steps_));
  ++steps_;
}

std::vector<real2> Solver::contact_forces() {
  std::vector<real2> out(arrays_.num_nodes);
  if (!contact_) return out;
  const auto acc = download<cl_long>(cl_, arrays_.contact_acc, 2 * arrays_.num_nodes);
  const double unit = 1.0 / contact_->force_scale();
  for (size_t i = 0; i < out.size(); ++i) out[i] = {real(acc[2 * i] * unit), real(acc[2 * i + 1] * unit)};
  return out;
}

void Solver::enqueue_stress() { triangle_forces_.enqueue(static_cast<int>(steps_), true); }

std::vector<real2> Solver::positions() { return download<real2>(cl_, arrays_.position, arrays_.num_nodes); }
std::vector<real2> Solver::velocities() { return download<real2>(cl_, arrays_.velocity, arrays_.num_nodes); }
std::vector<real2> Solver::forces() { return download<real2>(cl_, arrays_.node_force, arrays_.num_nodes); }
std::vector<real2> Solver::masses() { return download<real2>(cl_, arrays_.node_mass, arrays_.num_nodes); }
std::vector<real4> Solver::stresses() { return download<real4>(cl_, arrays_.stress, arrays_.num_triangles); }

Conditions Solver::conditions() {
  const auto words = download<int>(cl_, arrays_.conditions, 4);
  auto value = [](int w) { return w == INT_MAX ? -1 : w; };
  return {value(words[0]), value(words[1]), value(words[2]), value(words[3])};
}

void Solver::save_checkpoint() {
  const size_t bytes = arrays_.num_nodes * sizeof(real2);
  cl_.queue().enqueue_copy_buffer(arrays_.position, saved_position_, 0, 0, bytes);
  cl_.queue().enqueue_copy_buffer(arrays_.velocity, saved_velocity_, 0, 0, bytes);
  checkpoint_step_ = steps_;
}

void Solver::restore_checkpoint() {
  if (checkpoint_step_ < 0) return;
  const size_t bytes = arrays_.num_nodes * sizeof(real2);
  cl_.queue().enqueue_copy_buffer(saved_position_, arrays_.position, 0, 0, bytes);
  cl_.queue().enqueue_copy_buffer(saved_velocity_, arrays_.velocity, 0, 0, bytes);
  steps_ = checkpoint_step_;
  cl_.finish();
}

}  // namespace fdem
