// Heterogeneous materials ([material.heterogeneity]): the Weibull draws against the
// distribution they claim (statistics tests that fail for a wrong modulus or a biased
// generator), the same seed giving the same model and run bit for bit, and the arrays that
// exist only for the materials that use them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "case_files.hpp"
#include "engine/model/heterogeneity.hpp"
#include "engine/run/prepare_case.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

// Maximum-likelihood Weibull shape of `x` (scale free): the root of
// Σ x^k ln x / Σ x^k - 1/k - mean(ln x) = 0, by bisection on [0.05, 100].
double fitted_modulus(const std::vector<double>& x) {
  double mean_log = 0;
  for (double v : x) mean_log += std::log(v);
  mean_log /= double(x.size());
  auto g = [&](double k) {
    double a = 0, b = 0;
    for (double v : x) {
      const double p = std::pow(v, k);
      a += p * std::log(v);
      b += p;
    }
    return a / b - 1.0 / k - mean_log;
  };
  double lo = 0.05, hi = 100.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// Kolmogorov-Smirnov distance of `x` (scaled by 1/scale) from the Weibull CDF 1 - exp(-x^m).
double ks_distance(std::vector<double> x, double m, double scale = 1.0) {
  std::sort(x.begin(), x.end());
  const double n = double(x.size());
  double d = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double f = 1.0 - std::exp(-std::pow(x[i] / scale, m));
    d = std::max({d, std::fabs(f - double(i) / n), std::fabs(double(i + 1) / n - f)});
  }
  return d;
}

// The test bar, fracturable, with [material.heterogeneity] of the given keys.
std::string hetero_case(const std::string& heterogeneity, const std::string& size = "0.05") {
  test::BarCase c;
  c.mesh = "size = " + size + "\n";
  c.time = "dt = \"auto\"\nsteps = 200\n";
  c.output = "dir = \"out\"\nframes = 2\nhistory_every = 2e-5\n";
  c.material = R"(
[material.fracture]
tensile_strength = 2.0e6
cohesion = 6.0e6
friction_angle = 30.0
gf1 = 20.0
gf2 = 200.0
penalty = { opening = 500e9, sliding = 500e9, overlap = 500e9 }
)" + (heterogeneity.empty() ? "" : "[material.heterogeneity]\n" + heterogeneity);
  c.rest = R"(
[[boundary]]
region = "left"
fix = ["x", "y"]
[[boundary]]
region = "right"
velocity = [0.5, 0.0]
)";
  return c.text();
}

// The same keys with another seed.
std::string with_seed(std::string keys) {
  const size_t at = keys.find("seed = ");
  const size_t end = keys.find('\n', at);
  return keys.replace(at, end - at, "seed = 999");
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("Weibull draws: 100k factors have the requested modulus (MLE within 5%) and pass a KS test") {
  for (double m : {1.5, 3.0, 10.0}) {
    CAPTURE(m);
    std::vector<double> x(100000);
    for (size_t k = 0; k < x.size(); ++k) x[k] = weibull_factor(m, 2026, WeibullProperty::Young, k);
    const double fit = fitted_modulus(x);
    MESSAGE("m = " << m << ": fitted " << fit << ", KS sqrt(n) D = " << std::sqrt(1e5) * ks_distance(x, m));
    CHECK(std::fabs(fit / m - 1.0) < 0.05);
    // 1% critical value of the KS statistic: √n D < 1.63.
    CHECK(std::sqrt(double(x.size())) * ks_distance(x, m) < 1.63);
    // The mean is Γ(1 + 1/m) (scale 1).
    double mean = 0;
    for (double v : x) mean += v;
    mean /= double(x.size());
    CHECK(mean == doctest::Approx(std::tgamma(1.0 + 1.0 / m)).epsilon(0.01));
  }
  // The streams differ by seed and by property, and the same arguments give the same bits.
  CHECK(weibull_uniform(1, WeibullProperty::Young, 5) != weibull_uniform(2, WeibullProperty::Young, 5));
  CHECK(weibull_uniform(1, WeibullProperty::Young, 5) != weibull_uniform(1, WeibullProperty::Cohesion, 5));
  CHECK(weibull_factor(3, 9, WeibullProperty::TensileStrength, 77) ==
        weibull_factor(3, 9, WeibullProperty::TensileStrength, 77));
  // A wrong modulus is caught: draws of m = 3 fail the KS test for m = 3.3.
  std::vector<double> x(100000);
  for (size_t k = 0; k < x.size(); ++k) x[k] = weibull_factor(3.0, 2026, WeibullProperty::Young, k);
  CHECK(std::sqrt(double(x.size())) * ks_distance(x, 3.3) > 1.63);
}

TEST_CASE("[material.heterogeneity]: the model's E, T_s and c follow Weibull(m, value); same seed, same model") {
  test::TempDir dir;
  const std::string keys = "homogeneity = 4.0\nseed = 11\nproperties = [\"young\", \"tensile_strength\", \"cohesion\"]\n";
  const std::vector<std::string> out = {"output.dir=\"" + dir.str() + "/out\""};
  const PreparedCase a = prepare_case(dir.write("a.toml", hetero_case(keys, "0.02")), out);
  const PreparedCase b = prepare_case(dir.write("b.toml", hetero_case(keys, "0.02")), out);
  const PreparedCase other = prepare_case(dir.write("c.toml", hetero_case(with_seed(keys), "0.02")), out);
  REQUIRE(a.model.young_factor.size() == a.model.num_triangles());
  REQUIRE(a.model.ce4_strength_factor.size() == a.model.ce4.size());
  CHECK(std::memcmp(a.model.young_factor.data(), b.model.young_factor.data(),
                    a.model.young_factor.size() * sizeof(double)) == 0);
  CHECK(std::memcmp(a.model.ce4_strength_factor.data(), b.model.ce4_strength_factor.data(),
                    a.model.ce4_strength_factor.size() * sizeof(double) * 2) == 0);
  CHECK(a.model.young_factor != other.model.young_factor);
  // The drawn factors are Weibull(4) (scale 1: the value is the material's u₀ times it).
  std::vector<double> ts, c;
  for (const auto& f : a.model.ce4_strength_factor) ts.push_back(f[0]), c.push_back(f[1]);
  MESSAGE(a.model.num_triangles() << " TRI3, " << a.model.ce4.size() << " CE4s; fitted moduli E "
                                  << fitted_modulus(a.model.young_factor) << ", T_s " << fitted_modulus(ts) << ", c "
                                  << fitted_modulus(c));
  for (const std::vector<double>* v : std::vector<const std::vector<double>*>{&a.model.young_factor, &ts, &c}) {
    CHECK(std::sqrt(double(v->size())) * ks_distance(*v, 4.0) < 1.63);
    CHECK(fitted_modulus(*v) == doctest::Approx(4.0).epsilon(0.1));
  }
  CHECK(ts != c);  // independent streams
}

TEST_CASE("[material.heterogeneity]: the same seed gives the same run bitwise, another seed another run") {
  test::TempDir dir;
  const std::string keys = "homogeneity = 2.0\nseed = 5\nproperties = [\"young\", \"tensile_strength\"]\n";
  std::vector<std::vector<double>> sxx, energy;
  for (const std::string& k : {keys, keys, with_seed(keys)}) {
    test::TempDir out;
    const std::string path = out.write("bar.toml", hetero_case(k));
    test::run(path, {"output.dir=\"" + out.str() + "/out\""});
    sxx.push_back(test::read_variable(out.str() + "/out/bar.exo", "vals_elem_var1eb1"));
    energy.push_back(test::read_variable(out.str() + "/out/bar_history.nc", "strain_energy"));
  }
  REQUIRE(sxx[0].size() == sxx[1].size());
  CHECK(std::memcmp(sxx[0].data(), sxx[1].data(), sxx[0].size() * sizeof(double)) == 0);
  CHECK(std::memcmp(energy[0].data(), energy[1].data(), energy[0].size() * sizeof(double)) == 0);
  CHECK(sxx[0] != sxx[2]);
}

TEST_CASE("[material.heterogeneity]: the device holds factors only for what varies") {
  test::TempDir dir;
  auto plan = [&](const std::string& keys) {
    const PreparedCase p = prepare_case(dir.write("p.toml", hetero_case(keys)), {"output.dir=\"" + dir.str() + "/out\""});
    return std::make_pair(Solver::plan(p.model, test::context().group_size()), p.model.ce4.size());
  };
  auto bytes = [](const MemoryPlan& p, const std::string& name) {
    for (const auto& a : p.arrays())
      if (a.name == name) return a.bytes;
    return size_t(0);
  };
  const auto [none, ce4] = plan("");
  const auto [young, ce4b] = plan("homogeneity = 3.0\nseed = 1\nproperties = [\"young\"]\n");
  const auto [strength, ce4c] = plan("homogeneity = 3.0\nseed = 1\nproperties = [\"cohesion\"]\n");
  CHECK(bytes(none, "young_factor") == 0);
  CHECK(bytes(young, "young_factor") > 0);
  CHECK(bytes(strength, "young_factor") == 0);
  // One property row per set, plus one per CE4 whose strength varies.
  const size_t row = layout::COHP_STRIDE * sizeof(real);
  CHECK(bytes(none, "ce4_property_rows") == row);
  CHECK(bytes(young, "ce4_property_rows") == row);
  CHECK(bytes(strength, "ce4_property_rows") == row * (1 + ce4c));
}

}  // TEST_SUITE
