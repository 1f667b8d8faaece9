// Contact end to end: energy in impacts, friction on an incline, a settled stack,
// and skin rebuilds against rebuilding every step. The contact cases at full size
// (sliding, impact, stack) are validation runs (validation/, `make validate`).
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "approx.hpp"
#include "case_files.hpp"
#include "engine/device/checkpoint.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

std::vector<double> history(const test::TempDir& dir, const std::string& name, const std::string& var) {
  return test::read_variable(dir.str() + "/" + name + "_history.nc", var);
}

// A soft 5 cm block on the sliding case's base, gravity tilted by `degrees`.
std::string incline_case(const test::TempDir& dir, double degrees, const std::string& extra = "") {
  const double g = 9.81, a = degrees * M_PI / 180;
  std::ostringstream text;
  text.precision(17);
  text << "title = \"incline\"\n[mesh]\ngeo = \"" << test::source_path("cases/sliding/sliding.geo")
       << "\"\nsize = 0.025\n[time]\ndt = \"auto\"\nend = 0.2\n[output]\ndir = \"" << dir.str()
       << "\"\nframes = 2\nhistory_every = 0.005\nregions = [\"block\"]\n"
       << "[[material]]\nname = \"block\"\nregions = [\"block\"]\ndensity = 2000.0\nyoung = 1e8\npoisson = 0.25\nviscosity = 2e3\n"
       << "[[material]]\nname = \"base\"\nregions = [\"base\"]\ndensity = 2000.0\nyoung = 1e8\npoisson = 0.25\n"
       << "[gravity]\ng = [" << g * std::sin(a) << ", " << -g * std::cos(a) << "]\n"
       << "[contact]\nnormal_penalty = 1e8\nfriction = 0.5\ndamping = { exponent = 2.0 }\nrebuild = \"skin\"\nskin = 1e-3\n"
       << "[[boundary]]\nregion = \"base\"\nfix = [\"x\", \"y\"]\n"
       << extra;
  return dir.write("incline.toml", text.str());
}

// The same block and base with nothing that damps: no viscosity, no contact damping,
// μ = `mu`, and `tangential` the [contact] line for P_tan ("" for the default); 0.1 s.
std::string undamped_incline_case(const test::TempDir& dir, double degrees, double mu, const std::string& tangential) {
  const double g = 9.81, a = degrees * M_PI / 180;
  std::ostringstream text;
  text.precision(17);
  text << "title = \"undamped incline\"\n[mesh]\ngeo = \"" << test::source_path("cases/sliding/sliding.geo")
       << "\"\nsize = 0.025\n[time]\ndt = \"auto\"\nend = 0.1\n[output]\ndir = \"" << dir.str()
       << "\"\nframes = 2\nhistory_every = 0.005\nregions = [\"block\"]\n"
       << "[[material]]\nname = \"block\"\nregions = [\"block\"]\ndensity = 2000.0\nyoung = 1e8\npoisson = 0.25\n"
       << "[[material]]\nname = \"base\"\nregions = [\"base\"]\ndensity = 2000.0\nyoung = 1e8\npoisson = 0.25\n"
       << "[gravity]\ng = [" << g * std::sin(a) << ", " << -g * std::cos(a) << "]\n"
       << "[contact]\nnormal_penalty = 1e8\n" << tangential << "friction = " << mu << "\nrebuild = \"skin\"\nskin = 1e-3\n"
       << "[[boundary]]\nregion = \"base\"\nfix = [\"x\", \"y\"]\n";
  return dir.write("incline.toml", text.str());
}

}  // namespace

TEST_SUITE("contact") {

TEST_CASE("default tangential penalty: 6 P_n / h with h the mean triangle edge; check warns about a P_tan far from it") {
  test::TempDir dir;
  const std::string path = undamped_incline_case(dir, 19.62, 0.4, "");
  const PreparedCase p = prepare_case(path, {});
  const double h = mean_edge_length(p.model);
  CHECK(h == test::rel(5 * default_skin(p.model), 1e-12));  // the h of the default skin
  const double ptan = p.model.contact.pair_props[layout::PAIR_TANGENTIAL_PENALTY];
  CHECK(ptan == doctest::Approx(6 * 1e8 / h).epsilon(1e-12));
  MESSAGE("sliding mesh at size 0.025: mean edge h = " << h << " m, default P_tan = " << ptan << " Pa/m for P_n = 1e8 Pa");
  CHECK(ptan > 1e10);  // h is about 2 cm: hundreds of times the former default, 1e8 "Pa/m"
  CHECK(model_warnings(p.model, p.config).empty());
  // A pair without its own P_tan takes 6 × its own P_n / h.
  const PreparedCase paired = prepare_case(path, {"contact.pair=[{materials=[\"block\",\"base\"],normal_penalty=2e8}]"});
  const auto& pp = paired.model.contact;
  const uint32_t row = pp.pair_index[0 * 2 + 1];
  CHECK(pp.pair_props[row * layout::CONTACT_PROPS + layout::PAIR_TANGENTIAL_PENALTY] == doctest::Approx(6 * 2e8 / h));

  const PreparedCase soft = prepare_case(path, {"contact.tangential_penalty=1e8"});
  const auto warnings = model_warnings(soft.model, soft.config);
  REQUIRE(warnings.size() == 1);
  CHECK(doctest::String(warnings[0].c_str()) == doctest::Contains((path + " (from --set contact.tangential_penalty=1e8): contact.tangential_penalty = "
                                                 "1e+08 Pa/m is more than 10x away from 6 P_n / h").c_str()));
  // A pair that only inherits [contact]'s P_tan is not warned about twice; one with its
  // own P_n is, since its consistent value differs.
  const std::string pair = "contact.pair=[{materials=[\"block\",\"base\"]}]";
  const PreparedCase inherits = prepare_case(path, {"contact.tangential_penalty=1e8", pair});
  CHECK(model_warnings(inherits.model, inherits.config).size() == 1);
  const PreparedCase own_pn =
      prepare_case(path, {"contact.tangential_penalty=1e8", "contact.pair=[{materials=[\"block\",\"base\"],normal_penalty=2e8}]"});
  const auto both = model_warnings(own_pn.model, own_pn.config);
  REQUIRE(both.size() == 2);
  CHECK(doctest::String(both[1].c_str()) == doctest::Contains("contact.tangential_penalty (taken by contact.pair[0]) = 1e+08 Pa/m"));
  const auto off = model_warnings(prepare_case(path, {"contact.tangential_penalty=0"}).model,
                                  prepare_case(path, {"contact.tangential_penalty=0"}).config);
  REQUIRE(off.size() == 1);
  CHECK(doctest::String(off[0].c_str()) == doctest::Contains("contact.tangential_penalty = 0 turns the tangential contact force off, so friction = 0.4 has no effect"));
}

TEST_CASE("CE4 penalties below 10 E: check warns naming the key and the seed paper's section") {
  test::TempDir dir;
  test::BarCase bar;
  bar.time = "dt = \"auto\"\nsteps = 10\n";
  bar.output = "dir = \"" + dir.str() + "\"\n";
  bar.material = "[material.fracture]\ntensile_strength = 1e6\ncohesion = 2e6\nfriction_angle = 30.0\ngf1 = 10.0\ngf2 = 50.0\n"
                 "penalty = { opening = 10e9, sliding = 500e9, overlap = 500e9 }\n";
  const std::string path = dir.write("bar.toml", bar.text());
  const PreparedCase p = prepare_case(path, {});
  auto warnings = model_warnings(p.model, p.config);
  REQUIRE(warnings.size() == 1);
  CHECK(doctest::String(warnings[0].c_str()) == doctest::Contains((path + ":").c_str()));
  CHECK(doctest::String(warnings[0].c_str()) == doctest::Contains("material[0].fracture.penalty.opening = 1e+10 Pa is below 10 E = 1e+11 Pa"));
  CHECK(doctest::String(warnings[0].c_str()) == doctest::Contains("the seed paper (Section 3.4)"));
  const PreparedCase fine = prepare_case(path, {"material.0.fracture.penalty.opening=500e9"});
  CHECK(model_warnings(fine.model, fine.config).empty());
}

TEST_CASE("an undamped block on a 19.6 degree incline with μ = 0.4 sticks under the default P_tan") {
  // 0.9 × atan 0.4: static friction holds it, and nothing damps the bounce on the
  // contact springs. With P_tan = P_n numerically (the former default) it ratchets down
  // the slope (cases/sliding/README.md).
  test::TempDir still;
  test::run(undamped_incline_case(still, 19.62, 0.4, ""), {});
  const auto x = history(still, "incline", "block_disp_x");
  MESSAGE("undamped block, default P_tan: creep " << x.back() << " m in 0.1 s");
  CHECK(std::fabs(x.back()) < 5e-4 * 0.05);
  test::TempDir soft;
  test::run(undamped_incline_case(soft, 19.62, 0.4, "tangential_penalty = 1e8\n"), {});
  const auto x_soft = history(soft, "incline", "block_disp_x");
  MESSAGE("undamped block, P_tan = 1e8 Pa/m: creep " << x_soft.back() << " m in 0.1 s");
  CHECK(std::fabs(x_soft.back()) > 10 * std::fabs(x.back()));
}

TEST_CASE("disc impact: b = 1 returns the kinetic energy within 1%; b = 2, 5 lose more, as the contact's dissipation says") {
  const std::string impact = test::source_path("cases/impact/case.toml");
  std::vector<double> returned;
  for (double b : {1.0, 2.0, 5.0}) {
    CAPTURE(b);
    test::TempDir dir;
    std::ostringstream damping;
    damping << "contact.damping={exponent=" << b << "}";
    test::run(impact, {"mesh.size=0.02", "time.end=0.0016", "output.dir=\"" + dir.str() + "\"", damping.str()});
    const auto ke = history(dir, "impact", "kinetic_energy");
    const auto touching = history(dir, "impact", "contact_couples");
    const auto damping_lost = history(dir, "impact", "contact_damping_dissipation");
    const auto friction_lost = history(dir, "impact", "friction_dissipation");
    const double lost = damping_lost.back() + friction_lost.back();
    REQUIRE(touching.back() == 0);  // the disc has bounced off
    CHECK(ke.front() == doctest::Approx(4.1e3).epsilon(0.02));
    returned.push_back(ke.back() / ke.front());
    // Energy balance: what the disc lost is what contact damping dissipated (the rest,
    // a few %, stays as the disc's vibration).
    CHECK(ke.front() - ke.back() == doctest::Approx(lost).epsilon(0.05).scale(0.01 * ke.front()));
  }
  CHECK(returned[0] > 0.99);
  CHECK(returned[1] < returned[0] - 0.05);
  CHECK(returned[2] < returned[1] - 0.05);
}

TEST_CASE("a block on a 20 degree incline with μ = 0.5 stays put; at 30 degrees it slides with a = g(sin θ − μ cos θ)") {
  test::TempDir still;
  test::run(incline_case(still, 20.0), {});
  const auto x20 = history(still, "incline", "block_disp_x");
  CHECK(std::fabs(x20.back()) < 1e-3 * 0.05);  // creep below 0.1% of the block's size over 0.2 s

  test::TempDir slide;
  test::run(incline_case(slide, 30.0), {});
  const auto t = history(slide, "incline", "time");
  const auto x = history(slide, "incline", "block_disp_x");
  // Least-squares fit of x = x0 + v0 t + a t²/2 over the second half of the run.
  Eigen::MatrixXd A(0, 3);
  Eigen::VectorXd b(0);
  for (size_t k = t.size() / 2; k < t.size(); ++k) {
    A.conservativeResize(A.rows() + 1, 3);
    b.conservativeResize(b.size() + 1);
    A.row(A.rows() - 1) << 1.0, t[k], 0.5 * t[k] * t[k];
    b(b.size() - 1) = x[k];
  }
  const Eigen::Vector3d fit = A.colPivHouseholderQr().solve(b);
  const double expected = 9.81 * (std::sin(M_PI / 6) - 0.5 * std::cos(M_PI / 6));
  CHECK(fit(2) == doctest::Approx(expected).epsilon(0.02));
}

TEST_CASE("a settled stack: the base carries the total weight within 0.5%, overlaps below 1% of the element size") {
  test::TempDir dir;
  test::run(test::source_path("cases/stack/case.toml"), {"output.dir=\"" + dir.str() + "\"", "mesh.size=0.025", "time.end=0.01"});
  const double weight = 1800 * 9.81 * (0.3 * 0.02 + 3 * 0.1 * 0.05);
  CHECK(history(dir, "stack", "base_force_y").back() == doctest::Approx(weight).epsilon(0.005));
  const std::vector<std::pair<std::string, std::string>> faces = {
      {"base_top", "block1_bottom"}, {"block1_top", "block2_bottom"}, {"block2_top", "block3_bottom"}};
  for (const auto& [lower, upper] : faces) {
    const double overlap = history(dir, "stack", lower + "_disp_y").back() - history(dir, "stack", upper + "_disp_y").back();
    CHECK(overlap < 0.01 * 0.025);
  }
}

TEST_CASE("skin rebuilds give the same physics as rebuilding every step") {
  test::TempDir every, skin, thin, defaults;
  const std::string impact = test::source_path("cases/impact/case.toml");
  const std::vector<std::string> common = {"mesh.size=0.02", "time.end=0.0012", "contact.damping={exponent=2.0}",
                                           "contact.friction=0.3"};
  auto with = [&](const test::TempDir& dir, std::vector<std::string> extra) {
    extra.insert(extra.end(), common.begin(), common.end());
    extra.push_back("output.dir=\"" + dir.str() + "\"");
    return extra;
  };
  test::run(impact, with(every, {"contact.rebuild=\"step\""}));
  // A 2 mm skin is tested a few steps late (the host does not wait); a 2 µm skin is too
  // thin for the late test's margin at these speeds, so every step tests its own state.
  test::run(impact, with(skin, {"contact.rebuild=\"skin\"", "contact.skin=2e-3"}));
  test::run(impact, with(thin, {"contact.rebuild=\"skin\"", "contact.skin=2e-6"}));
  // Neither key (the case as written): the default skin, a fifth of the mean edge.
  test::run(impact, with(defaults, {}));
  for (const std::string var : {"kinetic_energy", "friction_dissipation", "contact_damping_dissipation", "contact_couples"}) {
    CAPTURE(var);
    const auto a = history(every, "impact", var), b = history(skin, "impact", var), c = history(thin, "impact", var),
               d = history(defaults, "impact", var);
    REQUIRE(a.size() == b.size());
    REQUIRE(a.size() == c.size());
    REQUIRE(a.size() == d.size());
    CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
    CHECK(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)) == 0);
    CHECK(std::memcmp(a.data(), d.data(), a.size() * sizeof(double)) == 0);
  }
  const auto rebuilds_skin = history(skin, "impact", "contact_rebuilds"), rebuilds_thin = history(thin, "impact", "contact_rebuilds"),
             rebuilds_every = history(every, "impact", "contact_rebuilds"),
             rebuilds_default = history(defaults, "impact", "contact_rebuilds");
  MESSAGE("contact rebuilds: every step " << rebuilds_every.back() << ", skin 2 mm " << rebuilds_skin.back()
                                          << ", skin 2 µm " << rebuilds_thin.back() << ", default skin "
                                          << rebuilds_default.back());
  CHECK(rebuilds_skin.back() < rebuilds_thin.back());
  CHECK(rebuilds_default.back() < rebuilds_every.back() / 4);  // the default is the fast path
  CHECK(history(skin, "impact", "contact_candidates").back() >= history(every, "impact", "contact_candidates").back());
  CHECK(history(defaults, "impact", "contact_candidates").back() >= history(every, "impact", "contact_candidates").back());
}

TEST_CASE("with couples listed ahead of joins the skin does not change the physics, also across a checkpoint") {
  // The blasting case, coarse (about 4,300 TRI3): CE4s near the hole break from the 50th
  // step on, and each break brings triangles into contact ("fractured"). Three skins: the
  // case's 0.1 mm (a detection every few steps, each step testing its own skin), 3 mm
  // (rare detections, the skin test read late) and "auto" (picked at each detection).
  // Before couples were listed ahead of joins, a join was seen up to 15 steps late with a
  // large skin, and a couple that started touching in those steps was taken for one met
  // over an overlap (no force): the runs parted (the coarse case at step 3,911). Now the
  // positions and velocities must be the same, bitwise, and the energy terms but for the
  // stored contact energy's sum (couple order: rounding); a fourth solver loaded from a
  // checkpoint of the "auto" one at step 90 continues bitwise as it.
  auto& cl = test::context();
  test::TempDir dir;
  auto prepared = [&](const std::string& skin) {
    return prepare_case(test::source_path("cases/blasting/case.toml"),
                        {"mesh.size=0.04", "contact.skin=" + skin, "output.dir=\"" + dir.str() + "\""});
  };
  const PreparedCase thin = prepared("1e-4"), wide = prepared("3e-3"), adaptive = prepared("\"auto\"");
  REQUIRE(thin.model.contact.list_ahead);
  Solver a(cl, thin.model, thin.dt), b(cl, wide.model, wide.dt), c(cl, adaptive.model, adaptive.dt);
  REQUIRE(c.skin()->adaptive());
  std::unique_ptr<Solver> resumed;
  for (int s = 1; s <= 400; ++s) {
    a.step(s % 10 == 0);
    b.step(s % 10 == 0);
    c.step(s % 10 == 0);
    if (resumed) resumed->step(s % 10 == 0);
    if (s == 90) {
      io::CheckpointData data;
      StateWriter out(cl, data);
      c.save_state(out);
      resumed = std::make_unique<Solver>(cl, adaptive.model, adaptive.dt);
      StateReader in(cl, data, "in memory");
      resumed->load_state(in);
    }
    if (s % 10 != 0) continue;
    CAPTURE(s);
    const auto x = a.positions(), v = a.velocities();
    for (Solver* other : {&b, &c}) {
      CHECK(std::memcmp(x.data(), other->positions().data(), x.size() * sizeof(real2)) == 0);
      CHECK(std::memcmp(v.data(), other->velocities().data(), v.size() * sizeof(real2)) == 0);
    }
    if (resumed) {
      CHECK(std::memcmp(x.data(), resumed->positions().data(), x.size() * sizeof(real2)) == 0);
      CHECK(std::memcmp(v.data(), resumed->velocities().data(), v.size() * sizeof(real2)) == 0);
    }
    const EnergyTotals ea = a.energy(), eb = b.energy(), ec = c.energy();
    CHECK(ea.kinetic == eb.kinetic);
    CHECK(ea.kinetic == ec.kinetic);
    CHECK(ea.strain == ec.strain);
    CHECK(ea.contact_stored == doctest::Approx(eb.contact_stored).epsilon(1e-12));
    CHECK(ea.contact_stored == doctest::Approx(ec.contact_stored).epsilon(1e-12));
  }
  MESSAGE("detections: skin 0.1 mm " << a.contact_rebuilds() << ", 3 mm " << b.contact_rebuilds() << ", auto "
                                     << c.contact_rebuilds() << " (skins " << c.skin()->smallest_skin() << " to "
                                     << c.skin()->largest_skin() << " m)");
  CHECK(b.contact_rebuilds() < a.contact_rebuilds());
  CHECK(c.contact_rebuilds() < a.contact_rebuilds());
  CHECK(a.cohesive()->count_broken() > 20);
}

TEST_CASE("fdem check warns when a case's own skin is crossed in a few steps") {
  // The blasting case with the 0.1 mm skin it had until 2026-12-03: a 1 GPa blast
  // (particle speed ~ 1e9 / (2880 x 5000) ≈ 69 m/s) and dt ~ 0.1 µs: a few steps. With a
  // wide skin or "auto" (the case's own now): no warning about it.
  test::TempDir dir;
  const std::string blasting = test::source_path("cases/blasting/case.toml");
  const std::string out = "output.dir=\"" + dir.str() + "\"";
  const PreparedCase own = prepare_case(blasting, {"mesh.size=0.04", out, "contact.skin=1e-4"});
  CHECK(speed_scale(own.model, own.config) == doctest::Approx(1e9 / std::sqrt(2880.0 * own.model.materials[0].wave_modulus)));
  auto mentions_skin = [](const std::vector<std::string>& warnings) {
    return std::any_of(warnings.begin(), warnings.end(), [](const std::string& w) { return w.find("contact.skin =") != std::string::npos; });
  };
  CHECK(mentions_skin(model_warnings(own.model, own.config, own.dt)));
  const PreparedCase wide = prepare_case(blasting, {"mesh.size=0.04", out, "contact.skin=0.02"});
  CHECK(!mentions_skin(model_warnings(wide.model, wide.config, wide.dt)));
  const PreparedCase adaptive = prepare_case(blasting, {"mesh.size=0.04", out});
  CHECK(adaptive.model.contact.skin_auto);
  CHECK(!mentions_skin(model_warnings(adaptive.model, adaptive.config, adaptive.dt)));
}

}  // TEST_SUITE
