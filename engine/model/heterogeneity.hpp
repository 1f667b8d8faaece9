// Heterogeneous materials ([material.heterogeneity], docs/case-format.md): per-element
// properties drawn from a Weibull distribution, the rule of RFPA-style models: an element's
// value is u₀ x with u₀ the material's own value and x of the density
// m x^(m-1) exp(-x^m) (shape m, the homogeneity index; scale 1). The draws depend only on
// the seed, the property and the element's rank within its material, so the same case
// gives the same model bit for bit, on any number of ranks.
#pragma once
#include <cstdint>

namespace fdem {

// The properties that can vary (their draws are independent streams of one seed).
enum class WeibullProperty : std::uint32_t { Young = 1, TensileStrength = 2, Cohesion = 3 };

// A uniform number in (0, 1) for (seed, property, index): a counter-based hash
// (SplitMix64 finaliser), 53 bits, never 0 or 1.
double weibull_uniform(std::uint64_t seed, WeibullProperty property, std::uint64_t index);

// The factor x = (-ln(1 - U))^(1/m) of element `index`, at least kWeibullFloor (so that no
// element loses practically all of its stiffness or strength: with m ≥ 1 fewer than 1 in
// 1,000 draws fall below it).
constexpr double kWeibullFloor = 1e-3;
double weibull_factor(double homogeneity, std::uint64_t seed, WeibullProperty property, std::uint64_t index);

}  // namespace fdem
