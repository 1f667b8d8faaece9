// Plain C++ (Eigen) reference of every kernel, written independently of the .cl code:
// tensors built index by index, shape-function gradients from edge normals rather than
// a matrix inverse. Tests compare the OpenCL stages against these.
#pragma once
#include <Eigen/Dense>
#include <array>
#include <cmath>

#include "engine/model/materials.hpp"

namespace fdem::reference {

using Eigen::Matrix2d;
using Eigen::Vector2d;

// 4th-order stiffness tensor C_ijkl from Voigt (xx, yy, xy with engineering shear).
inline double stiffness_tensor(const Voigt& c, int i, int j, int k, int l) {
  const double C3[3][3] = {{c[0], c[1], c[2]}, {c[1], c[3], c[4]}, {c[2], c[4], c[5]}};
  auto v = [](int a, int b) { return a == b ? a : 2; };
  return C3[v(i, j)][v(k, l)];
}

// Cauchy stress for deformation gradient F and velocity gradient L.
inline Matrix2d cauchy_stress(const MaterialConstants& m, const Matrix2d& F, const Matrix2d& L) {
  const double J = F.determinant();
  const Matrix2d I = Matrix2d::Identity();
  Matrix2d sigma;
  if (m.model == 0) {
    sigma = 0.5 * m.lambda * (J - 1.0 / J) * I + m.mu / J * (F * F.transpose() - I);
  } else {
    const Matrix2d E = 0.5 * (F.transpose() * F - I);
    Matrix2d S = Matrix2d::Zero();
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k)
          for (int l = 0; l < 2; ++l) S(i, j) += stiffness_tensor(m.c, i, j, k, l) * E(k, l);
    sigma = F * S * F.transpose() / J;
  }
  return sigma + m.viscosity * 0.5 * (L + L.transpose());
}

struct TriangleResult {
  std::array<Vector2d, 3> force;
  Matrix2d stress;
};

// Internal forces of one triangle: X reference, x current, v velocities (CCW order).
inline TriangleResult triangle_forces(const MaterialConstants& m, const std::array<Vector2d, 3>& X,
                                      const std::array<Vector2d, 3>& x, const std::array<Vector2d, 3>& v,
                                      double thickness) {
  auto gradients = [](const std::array<Vector2d, 3>& p) {
    const double area2 = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    std::array<Vector2d, 3> g;
    for (int a = 0; a < 3; ++a) {
      const Vector2d& pb = p[(a + 1) % 3];
      const Vector2d& pc = p[(a + 2) % 3];
      g[a] = Vector2d(pb.y() - pc.y(), pc.x() - pb.x()) / area2;  // inward normal of the opposite edge
    }
    return std::make_pair(g, 0.5 * area2);
  };
  const auto [G0, A0] = gradients(X);
  const auto [g, A] = gradients(x);
  Matrix2d F = Matrix2d::Zero(), L = Matrix2d::Zero();
  for (int a = 0; a < 3; ++a) {
    F += x[a] * G0[a].transpose();
    L += v[a] * g[a].transpose();
  }
  (void)A0;
  TriangleResult r;
  r.stress = cauchy_stress(m, F, L);
  for (int a = 0; a < 3; ++a) r.force[a] = -A * thickness * r.stress * g[a];
  return r;
}

}  // namespace fdem::reference

namespace fdem::reference {

// Small-strain tangent stiffness tensor of a material (Neo-Hookean: λ, μ isotropic).
inline double tangent(const MaterialConstants& m, int i, int j, int k, int l) {
  if (m.model == 0) return m.lambda * (i == j) * (k == l) + m.mu * ((i == k) * (j == l) + (i == l) * (j == k));
  return stiffness_tensor(m.c, i, j, k, l);
}

// The 6x6 small-strain stiffness matrix of a triangle (dof 2a+i), reference shape X.
inline Eigen::Matrix<double, 6, 6> element_stiffness(const MaterialConstants& m, const std::array<Vector2d, 3>& X,
                                                     double thickness) {
  const double area = 0.5 * ((X[1] - X[0]).x() * (X[2] - X[0]).y() - (X[1] - X[0]).y() * (X[2] - X[0]).x());
  std::array<Vector2d, 3> g;
  for (int a = 0; a < 3; ++a) {
    const Vector2d& pb = X[(a + 1) % 3];
    const Vector2d& pc = X[(a + 2) % 3];
    g[a] = Vector2d(pb.y() - pc.y(), pc.x() - pb.x()) / (2 * area);
  }
  Eigen::Matrix<double, 6, 6> K = Eigen::Matrix<double, 6, 6>::Zero();
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < 2; ++i)
      for (int b = 0; b < 3; ++b)
        for (int k = 0; k < 2; ++k)
          for (int j = 0; j < 2; ++j)
            for (int l = 0; l < 2; ++l) K(2 * a + i, 2 * b + k) += area * thickness * tangent(m, i, j, k, l) * g[a](j) * g[b](l);
  return K;
}

}  // namespace fdem::reference
