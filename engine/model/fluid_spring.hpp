// The fluid's spring in the mechanical step ([fluid]; docs/case-format.md, "The fluid's
// spring"): a vertex of two segments at the residual aperture holds V = h t w_r and a face
// node moving δ changes it by (3/4) h t δ, so the fluid pushes back with k = K_f ((3/4) h
// t)² / V = (9/16) K_f h t / w_r; a face node of mass m against the other face's is stable
// while Δt < √(2 m / k). Not part of the mechanical stable step: reported by `fdem check`
// and warned about (model_warnings).
#pragma once
#include <cstddef>

namespace fdem {

struct Model;

struct FluidSpring {
  double dt = 0;    // [s]: the smallest √(2 m / k) over the CE4s (any may break)
  size_t ce4 = 0;   // the CE4 it is at (the lightest of its four nodes, unscaled masses)
};

// Over model.ce4 with model.fluid's K_f and w_r (the model must have [fluid]).
FluidSpring fluid_spring(const Model& model);

}  // namespace fdem
