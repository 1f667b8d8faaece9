// Layouts shared by the host and the kernels, each written once here. The host uses the
// enumerators (layout::MAT_LAMBDA); every program is compiled with the same names as
// #defines (ClContext::build prepends layout_defines()), so a .cl file and the C++ that
// fills its arrays cannot disagree. A new field is one line in one list below.
#pragma once
#include <map>
#include <string>

namespace fdem::layout {

// The material table: MATERIAL_STRIDE reals per material (materials.cpp fills the rows).
#define FDEM_MATERIAL_LAYOUT(X)                                                              \
  X(MAT_MODEL, 0)      /* 0 Neo-Hookean (Eq. 1), 1 hyperelastic (Eqs. 2-3) */                \
  X(MAT_LAMBDA, 1)     /* Lamé λ of the 2D model [Pa] (plane stress: 2λμ/(λ+2μ)) */           \
  X(MAT_MU, 2)         /* shear modulus μ [Pa] */                                            \
  X(MAT_C11, 3)        /* Voigt stiffness, global frame, on (xx, yy, 2xy) [Pa] */            \
  X(MAT_C12, 4)                                                                              \
  X(MAT_C16, 5)                                                                              \
  X(MAT_C22, 6)                                                                              \
  X(MAT_C26, 7)                                                                              \
  X(MAT_C66, 8)                                                                              \
  X(MAT_VISCOSITY, 9)  /* η of the viscous stress η D [Pa s] */                              \
  X(MAT_DENSITY, 10)   /* ρ [kg/m³] */                                                       \
  X(MAT_RESERVED, 11)  /* unused */                                                          \
  X(MATERIAL_STRIDE, 12)

// The condition words (DeviceArrays::conditions): the first (lowest-index) offender of
// each kind and its step; INT_MAX while there is none.
#define FDEM_CONDITION_LAYOUT(X)                                                             \
  X(COND_BAD_NODE, 0)       /* node whose position or velocity became NaN/inf */             \
  X(COND_BAD_NODE_STEP, 1)                                                                   \
  X(COND_INVERTED_TRI, 2)   /* triangle whose Jacobian became <= 0 */                        \
  X(COND_INVERTED_STEP, 3)                                                                   \
  X(CONDITION_WORDS, 4)

// One slot of the monitor ring (engine/stages/monitor_ring.hpp): RING_WORDS uints.
#define FDEM_RING_LAYOUT(X)                                                                  \
  X(RING_MOVED, 0)   /* largest move since the last detection (float bits, atomic_max) */     \
  X(RING_SPEED, 1)   /* largest speed (float bits, atomic_max) */                             \
  X(RING_JOINED, 2)  /* 1: triangles joined the contact candidates this step */               \
  X(RING_POOL, 3)    /* contact history pool rows taken before this step (ContactForces) */   \
  X(RING_WORDS, 4)

// Per-CE4 parameter row (CohesiveForces computes it on the host, CohesiveForces::parameters):
// COH_STRIDE reals, the ones that depend on the CE4's own length. The device keeps only h
// ("ce4_length"): the kernel forms o_p, s_p and o_overlap from h and the CE4's property
// row (COHP_PO, COHP_PS, COHP_POV) with the same operations in the same order, so the
// same bits, and a CE4 holds 8 bytes instead of 32 (session 10: memory).
#define FDEM_COHESIVE_LAYOUT(X)                                                              \
  X(COH_OP, 0)      /* o_p = 2 h T_s / P_f [m] (Eq. 6) */                                    \
  X(COH_SP, 1)      /* s_p = 2 h c / P_tan [m] (Eq. 7) */                                    \
  X(COH_OOV, 2)     /* o_overlap = 2 h T_s / P_overlap [m] (Eq. 8) */                        \
  X(COH_H, 3)       /* initial edge length h [m]: the reference length of the tractions */   \
  X(COH_STRIDE, 4)

// Per fracture property set (a fracturable material or an interface; each CE4 names one):
// COHP_STRIDE reals. Shared by all its CE4s, so a CE4 reads 1 real of its own (h), not 12.
#define FDEM_COHESIVE_PROPERTY_LAYOUT(X)                                                     \
  X(COHP_OT, 0)      /* o_t = G_fI / (T_s I_f) [m] */                                        \
  X(COHP_ST, 1)      /* s_t = G_fII / (c I_f) [m] */                                         \
  X(COHP_TS, 2)      /* tensile strength T_s [Pa] */                                         \
  X(COHP_C, 3)       /* cohesion c [Pa] */                                                   \
  X(COHP_TANPHI, 4)  /* tan φ */                                                             \
  X(COHP_A, 5)       /* softening shape A, B, C (Eq. 10) */                                  \
  X(COHP_B, 6)                                                                               \
  X(COHP_CEXP, 7)                                                                            \
  X(COHP_PO, 8)      /* opening penalty P_f [Pa] */                                          \
  X(COHP_PS, 9)      /* sliding penalty P_tan [Pa] */                                        \
  X(COHP_POV, 10)    /* overlap penalty P_overlap [Pa] */                                    \
  X(COHP_STRIDE, 11)

// Per contact couple: CONTACT_HISTORY reals; 0-5 the slip of each edge pass, then these.
#define FDEM_CONTACT_HISTORY_LAYOUT(X)                                                       \
  X(HIST_OVERLAP_MAX, 6)  /* o_n_max (damped couples; σ there is min(P_n o_n_max, T)) */     \
  X(HIST_RATIO, 7)        /* σ/σ_try of the last step (damped couples) */                    \
  X(HIST_ENERGY, 8)       /* E of the last step (damped couples) */                          \
  X(HIST_PENDING, 9)      /* what the friction springs dissipate if the couple lets go */    \
  X(HIST_HELD, 10)        /* work done on the damped normal force not yet dissipated */      \
  X(HIST_REST, 11)        /* friction dissipated, not yet booked: below the accumulator's unit */ \
  X(CONTACT_HISTORY, 12)

// Per unordered material pair (ContactModel::pair_props): CONTACT_PROPS reals.
#define FDEM_CONTACT_PROPS_LAYOUT(X)                                                         \
  X(PAIR_NORMAL_PENALTY, 0)      /* P_n [Pa] */                                              \
  X(PAIR_TANGENTIAL_PENALTY, 1)  /* P_tan [Pa/m] */                                          \
  X(PAIR_FRICTION, 2)            /* μ */                                                     \
  X(PAIR_TENSILE, 3)             /* T [Pa] (damped couples) */                               \
  X(PAIR_DAMPING, 4)             /* b of Eq. 15 */                                           \
  X(PAIR_DAMPED, 5)              /* 1: Eq. 15 applies */                                     \
  X(CONTACT_PROPS, 8)

// The contact stage's cumulative dissipation words (64-bit fixed point).
#define FDEM_CONTACT_ENERGY_LAYOUT(X)                                                        \
  X(ENERGY_FRICTION, 0)                                                                      \
  X(ENERGY_DAMPING, 1)                                                                       \
  X(CONTACT_ENERGY_WORDS, 2)

// Kinds of loaded edge (model.hpp LoadKind has the same values; static_asserts in model.cpp).
#define FDEM_LOAD_KIND_LAYOUT(X)                                                             \
  X(LOAD_TRACTION, 0)                                                                        \
  X(LOAD_PRESSURE, 1)                                                                        \
  X(LOAD_BLAST, 2)                                                                           \
  X(LOAD_TABLE, 3)                                                                           \
  X(LOAD_ABSORBING, 4)                                                                       \
  X(LOAD_IN_SITU, 5)   /* two rows: (kind, σ₀ at the datum), (datum, dσ/d depth) */          \
  X(LOAD_GAS, 6)       /* [fluid.gas]: the pressure gas_hole[0].x of the fluid stage */

#define FDEM_LAYOUT_ENUMERATOR(name, value) name = value,
enum Material : int { FDEM_MATERIAL_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum Condition : int { FDEM_CONDITION_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum Ring : int { FDEM_RING_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum Cohesive : int { FDEM_COHESIVE_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum CohesiveProperty : int { FDEM_COHESIVE_PROPERTY_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum ContactHistory : int { FDEM_CONTACT_HISTORY_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum ContactProps : int { FDEM_CONTACT_PROPS_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum ContactEnergy : int { FDEM_CONTACT_ENERGY_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
enum LoadKind : int { FDEM_LOAD_KIND_LAYOUT(FDEM_LAYOUT_ENUMERATOR) };
#undef FDEM_LAYOUT_ENUMERATOR

// Every name above with its value, as the kernels' #defines.
inline const std::map<std::string, std::string>& defines() {
  static const std::map<std::string, std::string> all = [] {
    std::map<std::string, std::string> d;
#define FDEM_LAYOUT_DEFINE(name, value) d[#name] = std::to_string(value);
    FDEM_MATERIAL_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_CONDITION_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_RING_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_COHESIVE_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_COHESIVE_PROPERTY_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_CONTACT_HISTORY_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_CONTACT_PROPS_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_CONTACT_ENERGY_LAYOUT(FDEM_LAYOUT_DEFINE)
    FDEM_LOAD_KIND_LAYOUT(FDEM_LAYOUT_DEFINE)
#undef FDEM_LAYOUT_DEFINE
    return d;
  }();
  return all;
}

}  // namespace fdem::layout
