// Plain host data of the cohesive elements (CE4s): connectivity, fracture properties per
// material or interface, and the softening function of Eq. 10 with its integral.
// The device stage is engine/stages/cohesive_forces.*; the law is in cl_kernels/cohesive_forces.cl.
#pragma once
#include <array>
#include <string>
#include <vector>

namespace fdem {

struct FractureProperties {           // one per fracturable material or interface
  double tensile_strength;            // T_s [Pa]
  double cohesion;                    // c [Pa]
  double friction_angle;              // φ [deg]
  double gf1, gf2;                    // G_fI, G_fII [J/m²]
  double penalty_opening, penalty_sliding, penalty_overlap;  // P_f, P_tan, P_overlap [Pa]
  double a = 0.63, b = 1.8, c = 6.0;  // softening shape, Eq. 10
  bool extrinsic = false;             // fracture.model = "extrinsic" (cl_kernels/extrinsic.cl)
};

// f(D) of Eq. 10: f(0) = 1, f(1) = 0, decreasing in between for the usual A, B, C.
double softening(double D, double a, double b, double c);
// I_f = ∫₀¹ f(D) dD, by adaptive Simpson to 1e-12 (≈ 0.38631 for 0.63, 1.8, 6.0). Throws
// NumericalError when f is not finite somewhere or the panels do not converge within
// kSofteningPanels evaluations (never recurses without bound).
double softening_integral(double a, double b, double c);
constexpr long kSofteningPanels = 1L << 20;

// What is wrong with the softening curve of a, b, c for the CE4 law, or "" when it is a
// curve the law can use: f finite on [0, 1], f(0) = 1 and f(1) = 0 to round-off, never
// rising (the kernel keeps the smallest f reached, so a rising stretch would be cut off
// and the dissipated energy would no longer be G_f), and I_f computable. Checked on 1001
// points; the case reader calls it for every `softening` table.
std::string softening_curve_problem(double a, double b, double c);

struct CohesiveModel {
  // Nodes (i, j, j', i'): edge i→j of triangle 1 (counter-clockwise, so its interior is
  // on the left of i→j), and its twin j'→i' of triangle 2 (i' coincides with i, j' with j).
  std::vector<std::array<int, 4>> ce4;
  std::vector<int> properties;           // index into `fracture` per CE4
  std::vector<FractureProperties> fracture;
  double thickness = 1.0;                // out-of-plane thickness t [m]
  // With contact (else empty): per node the mesh node it copies (Model::node_origin; a
  // CE4's mesh nodes are those of its i and j) and, per mesh node, 1 when its fan is
  // bonded (Model::vertex_bonded). The stage then keeps a state word per mesh
  // node, 0 while every CE4 at a bonded node is intact, 2 + n from the step n one of them
  // broke, -1 for a node whose fan is not bonded (corner couples there are contact couples).
  std::vector<int> node_origin;
  std::vector<int> vertex_bonded;
  // [material.heterogeneity] (else empty): per CE4 the factors on T_s and c of its set
  // (Model::ce4_strength_factor). A CE4 whose factors are not (1, 1) gets a property set of
  // its own, with the same fracture energies.
  std::vector<std::array<double, 2>> strength_factor;
  // [[joint]] broken = true (else empty): per CE4 1 where it starts closed (broken, its
  // faces touching: the compression branch and friction only), 0 where it starts intact.
  std::vector<char> closed;
  // [[excavation]] (else empty): per CE4 the excavations of its two triangles (-1: none;
  // Model::triangle_excavation), and per excavation (start, duration) [s]. A CE4 with
  // either one ramps with the smaller factor (cl_kernels/cohesive_forces.cl, EXCAVATION).
  std::vector<std::array<int, 2>> excavation_of;
  std::vector<std::array<double, 2>> excavation_times;
  // The run's time step [s]: the work term's displacements are velocity × dt, and the
  // excavation factors are taken at step × dt.
  double dt = 0;
  // [fluid] on: the CE4s that start to carry fluid in a step are appended to a list the
  // fluid stage reads (CohesiveForces::fluid_carriers): 1 where a broken CE4 carries, 2
  // where a softened one does too (fluid.segments = "damaged"); 0 without [fluid].
  int fluid_carriers = 0;
  // Contact activation "fractured" with couples listed ahead of joins, on one rank: the
  // CE4 that breaks marks its two triangles as contact candidates itself
  // (ACTIVATE_ON_BREAK), in place of ContactActivation's launch in every step; the
  // solver binds the arrays (CohesiveForces::join_on_break).
  bool activate_on_break = false;
};

// The property sets the stage holds for `model`'s CE4s: one per set of `fracture`, plus
// one per CE4 whose strength factors are not (1, 1).
size_t cohesive_property_sets(const CohesiveModel& model);

}  // namespace fdem
