// The initial (in-situ) stress field of a case ([in_situ], docs/case-format.md) and what
// it asks of each element: the triangles' reference stress and the CE4s' initial gaps.
// Tension positive. A body started in this state is in equilibrium to round-off when the
// field is (docs/energy-notes.md, "In-situ stress").
#pragma once
#include <array>
#include <string>

#include "engine/model/cohesive_model.hpp"

namespace fdem {

// σ₀(y) = uniform + (datum - y) × gradient: (σxx, σyy, σxy) [Pa]. A field that grows with
// depth below `datum` has gradient (−ρ g k_x, −ρ g, 0); a uniform one gradient 0.
struct InSituField {
  bool enabled = false;
  std::array<double, 3> uniform{0.0, 0.0, 0.0};   // [Pa]
  double datum = 0.0;                             // y of the surface [m]
  std::array<double, 3> gradient{0.0, 0.0, 0.0};  // [Pa/m] of depth
  std::array<double, 3> at(double y) const {
    const double depth = datum - y;
    return {uniform[0] + depth * gradient[0], uniform[1] + depth * gradient[1], uniform[2] + depth * gradient[2]};
  }
};

// What a CE4 needs to carry the field without moving: at each Gauss point an opening and
// a slip to add to the geometric ones (the law then gives the field's normal and shear
// tractions at o = s = 0), and the initial slip of its friction element.
struct InSituGaps {
  std::array<double, 3> opening{0.0, 0.0, 0.0};  // o₀ [m] (≤ 0: on the compression branch)
  std::array<double, 3> slip{0.0, 0.0, 0.0};     // s₀ [m]
  std::array<double, 3> friction_slip{0.0, 0.0, 0.0};  // s_f at the start [m]
};

// The gaps of the CE4 on edge a → b (reference positions, triangle 1 on the left) of
// initial length h with properties f, or the reason it cannot carry the field: tension
// across it (the field's normal traction > 0 at a Gauss point), or a shear traction above
// what it holds before softening, c + min(2c, tanφ |σ_n|). `problem` names the value and
// the place; empty when the gaps are set.
InSituGaps in_situ_gaps(const InSituField& field, const FractureProperties& f, std::array<double, 2> a,
                        std::array<double, 2> b, std::string& problem);

}  // namespace fdem
