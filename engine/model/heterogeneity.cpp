#include "engine/model/heterogeneity.hpp"

#include <algorithm>
#include <cmath>

namespace fdem {
namespace {

std::uint64_t mix(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace

double weibull_uniform(std::uint64_t seed, WeibullProperty property, std::uint64_t index) {
  const std::uint64_t stream = mix(seed ^ mix(static_cast<std::uint64_t>(property)));
  const std::uint64_t bits = mix(stream + mix(index)) >> 11;  // 53 bits
  return (static_cast<double>(bits) + 0.5) * 0x1.0p-53;
}

double weibull_factor(double homogeneity, std::uint64_t seed, WeibullProperty property, std::uint64_t index) {
  const double u = weibull_uniform(seed, property, index);
  return std::max(kWeibullFloor, std::pow(-std::log1p(-u), 1.0 / homogeneity));
}

}  // namespace fdem
