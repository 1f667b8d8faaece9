#include "engine/bench.hpp"

#include <algorithm>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>

#include "engine/device/device_arrays.hpp"
#include "base/errors.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "engine/stages/cohesive_forces.hpp"
#include "engine/stages/contact_skin.hpp"
#include "engine/stages/fluid_flow.hpp"

namespace fdem {

namespace {

constexpr long kBenchRowEvery = 100;  // steps between energy rows in the timed runs

// Table 2 of the seed paper: h_ave [mm] → (TRI3, Quadro GP100 seconds per 10,000 steps).
const std::map<double, std::pair<long, double>> kPaper = {
    {0.6, {60346, 126}}, {0.5, {86570, 134}}, {0.4, {136774, 146}},
    {0.3, {241298, 214}}, {0.2, {540754, 392}}, {0.15, {1084398, 846}}};

// Bytes one step must move at least (the bound printed as "roofline"; H200 about
// 4.3 TB/s): node state read and written, forces and masses read; every triangle's
// nodes, inverse shape matrix and corner forces; every CE4's nodes, parameters and
// Gauss-point state; every candidate couple's key, history and node positions read,
// and the touching ones' history written, velocities read and forces added.
double bytes_per_step(const Model& m, size_t couples, size_t touching) {
  const double r = sizeof(real);
  const double nodes = m.num_nodes() * (2 * r * 2 * 2 + 2 * r * 2 + 4);
  const double tris = m.num_triangles() * (12 + 4 * r + 4 + 3 * 2 * r * 2 + 3 * 2 * r);
  // CE4: nodes, parameters, Gauss-point state read and written, status, positions, the
  // four slots written, and the energy account (last step's slots and gaps read, work
  // read and written).
  const double ce4 = m.ce4.size() * (16 + 12 * r + 2 * 12 * r + 8 + 4 * 2 * r * 2 + 16 * r);
  const double contact = couples * (8 + 10 * r + 6 * 2 * r) + touching * (10 * r + 6 * 2 * r + 6 * 16);
  return nodes + tris + ce4 + contact;
}

// The gmsh size [m] for a row. Table 2's h_ave and TRI3 counts do not follow one
// area law (0.6 → 0.15 mm is 16× the area per triangle, its counts differ 18×), so the
// rows of Table 2 take the size that gives its TRI3 count on cases/ucs/ucs.geo, where
// gmsh makes about 15,630 mm² / size² triangles (measured at 0.51 and 0.1275 mm:
// 60,184 and 960,030); other rows take 0.85 h_ave.
double gmsh_size(double h_ave_mm) {
  const auto it = kPaper.find(h_ave_mm);
  if (it == kPaper.end()) return 0.85e-3 * h_ave_mm;
  return 1e-3 * std::sqrt(15630.0 / static_cast<double>(it->second.first));
}

struct FracturingRow {
  std::string name, case_path;
  int refine = 0;
  double window = 0;  // simulated seconds timed; 0: the case's whole run
};

FracturingRow fracturing_row(const std::string& name, const BenchOptions& o) {
  FracturingRow row{name, "", 0, 0};
  if (name == "ucs-fast") {
    row.case_path = o.cases_dir + "/ucs/fast.toml";
    return row;
  }
  row.case_path = o.cases_dir + "/blasting/case.toml";
  row.window = o.blast_window;
  if (name.size() == 10 && name.compare(0, 9, "blasting:") == 0 && name[9] >= '0' && name[9] <= '3')
    row.refine = name[9] - '0';
  return row;
}

// What one fracturing row measured.
struct FracturingResult {
  size_t tri3 = 0, ce4 = 0, broken = 0;
  long steps = 0, detections = 0;
  double skin_lo = 0, skin_hi = 0;  // the skins the run used [m] (fixed: both the case's)
  double seconds = 0, ms_per_detection = 0, used_bytes = 0, planned_bytes = 0;
};

// Steps the row's case as `fdem run` does (no output; an energy row every kBenchRowEvery
// steps) on `timed` for its window, then times detections of the broken model.
FracturingResult run_fracturing(const FracturingRow& row, const std::vector<std::string>& overrides, ClContext& timed) {
  if (!std::filesystem::exists(row.case_path))
    throw InputError("fdem bench --fracturing: " + row.case_path +
                     " not found (run from the source tree, or give --cases DIR)");
  const std::string dir = (std::filesystem::temp_directory_path() / "fdem-bench").string();
  std::vector<std::string> keys{"mesh.refine=" + std::to_string(row.refine), "output.dir=\"" + dir + "\""};
  keys.insert(keys.end(), overrides.begin(), overrides.end());
  const PreparedCase p = prepare_case(row.case_path, keys);
  FracturingResult r;
  r.tri3 = p.model.num_triangles();
  r.ce4 = p.model.ce4.size();
  r.steps = row.window > 0 ? std::min<long>(p.steps, std::lround(row.window / p.dt)) : p.steps;
  r.planned_bytes = static_cast<double>(Solver::bytes_needed(p.model, timed.group_size()));
  const size_t before_bytes = timed.device_bytes_in_use();
  Solver solver(timed, p.model, p.dt, true);
  timed.finish();
  const auto start = std::chrono::steady_clock::now();
  for (long s = 0; s < r.steps; ++s) solver.step((s + 1) % kBenchRowEvery == 0);
  timed.finish();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.detections = solver.contact_rebuilds();
  if (ContactSkin* skin = solver.skin()) {
    r.skin_lo = skin->adaptive() && skin->smallest_skin() > 0 ? skin->smallest_skin() : p.model.contact.skin;
    r.skin_hi = std::max(r.skin_lo, skin->largest_skin());
  }
  r.broken = solver.cohesive() ? solver.cohesive()->count_broken() : 0;
  r.used_bytes = static_cast<double>(timed.device_bytes_in_use() - before_bytes);
  r.ms_per_detection = solver.has_contact() ? solver.time_detections(20) : 0;
  return r;
}

// What one fluid row measured: the same model and steps with its [fluid] stage and without.
struct FluidResult {
  size_t tri3 = 0, ce4 = 0, vertices = 0, broken = 0;
  long steps = 0, substeps = 0;
  double seconds = 0, seconds_without = 0;
};

// cases/kgd/viscosity.toml split `refine` times, its first `window` seconds: once as `fdem
// run` steps it, once with the fluid stage taken out of the same prepared model (the seed
// crack's CE4s then stay intact; nothing else changes what a step costs).
FluidResult run_fluid_row(int refine, double window, const BenchOptions& o, ClContext& timed) {
  const std::string path = o.cases_dir + "/kgd/viscosity.toml";
  if (!std::filesystem::exists(path))
    throw InputError("fdem bench --fluid: " + path + " not found (run from the source tree, or give --cases DIR)");
  const std::string dir = (std::filesystem::temp_directory_path() / "fdem-bench").string();
  std::vector<std::string> keys{"mesh.refine=" + std::to_string(refine), "output.dir=\"" + dir + "\""};
  keys.insert(keys.end(), o.overrides.begin(), o.overrides.end());
  PreparedCase p = prepare_case(path, keys);
  FluidResult r;
  r.tri3 = p.model.num_triangles();
  r.ce4 = p.model.ce4.size();
  r.vertices = p.model.fluid.vertices;
  r.steps = std::min<long>(p.steps, std::max(1L, std::lround(window / p.dt)));
  r.substeps = FluidFlow::substeps(p.model.fluid, p.dt);
  auto time_steps = [&](const Model& model, size_t* broken) {
    Solver solver(timed, model, p.dt, true);
    timed.finish();
    const auto start = std::chrono::steady_clock::now();
    for (long s = 0; s < r.steps; ++s) solver.step((s + 1) % kBenchRowEvery == 0);
    timed.finish();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (broken) *broken = solver.cohesive() ? solver.cohesive()->count_broken() : 0;
    return seconds;
  };
  r.seconds = time_steps(p.model, &r.broken);
  p.model.fluid.enabled = false;
  r.seconds_without = time_steps(p.model, nullptr);
  return r;
}

// "0.1" or "0.1-2.3" [mm].
std::string skin_range(double lo, double hi) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(lo < 1e-3 ? 3 : 2) << 1e3 * lo;
  if (hi > lo * (1 + 1e-9)) o << "-" << std::setprecision(2) << 1e3 * hi;
  return o.str();
}

}  // namespace

std::vector<std::string> fracturing_rows(const std::string& list) {
  std::vector<std::string> rows;
  std::istringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "all") {
      for (const char* r : {"blasting", "blasting:2", "blasting:3", "ucs-fast"}) rows.push_back(r);
      continue;
    }
    const bool blast = item == "blasting" ||
                       (item.size() == 10 && item.compare(0, 9, "blasting:") == 0 && item[9] >= '0' && item[9] <= '3');
    if (!blast && item != "ucs-fast")
      throw InputError("--fracturing: unknown row '" + item +
                       "' (blasting, blasting:K with K = 0 to 3 levels of mesh.refine, ucs-fast, or all)");
    rows.push_back(item);
  }
  if (rows.empty()) throw InputError("--fracturing needs a list of rows (blasting, blasting:2, ucs-fast, all)");
  return rows;
}

std::vector<std::string> fluid_rows(const std::string& list) {
  std::vector<std::string> rows;
  std::istringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item != "kgd" && !(item.size() == 5 && item.compare(0, 4, "kgd:") == 0 && item[4] >= '0' && item[4] <= '3'))
      throw InputError("--fluid: unknown row '" + item + "' (kgd, or kgd:K with K = 0 to 3 levels of mesh.refine)");
    rows.push_back(item);
  }
  if (rows.empty()) throw InputError("--fluid needs a list of rows (kgd, kgd:1, kgd:2)");
  return rows;
}

int run_bench(const BenchOptions& o, const std::string& device, std::ostream& out) {
  // Two queues on the device: the step time is taken on a plain one (profiling events
  // cost host time per launch), the per-stage breakdown on a profiling one.
  ClContext timed(device, false);
  ClContext cl(device, true);
  const double bandwidth = cl.info().is_gpu ? 4.3e12 : 0.0;  // H200 figure; no CPU bound printed
  std::ostringstream csv;
  csv << "h_ave_mm,tri3,ce4,nodes,initial_couples,touching,rebuilds,ms_per_step,paper_ms_per_step,speedup,"
         "device_mib,bytes_per_tri3,roofline_ms,roofline_fraction,ms_per_step_without_account,planned_mib\n";
  out << "fdem bench on " << cl.description() << "\n";
  for (const auto& o_set : o.overrides) out << "every row with --set " << o_set << "\n";
  if (!o.sizes.empty()) {
    out << o.warmup << " warm-up + " << o.steps
        << " timed steps, dt 0.5 ns (halved per mesh.refine level), activation \"all\", skin 0.15 h_ave (rebuild when exceeded);\n"
        << "ms/step on a plain queue with the energy account (a row every " << kBenchRowEvery
        << " steps), no-account without it (same process); the stage times below from a run on a profiling queue\n";
    out << std::setw(6) << "h_ave" << std::setw(10) << "TRI3" << std::setw(10) << "CE4" << std::setw(10) << "nodes"
        << std::setw(11) << "couples" << std::setw(9) << "touch" << std::setw(6) << "rebd" << std::setw(11)
        << "ms/step" << std::setw(9) << "GP100" << std::setw(9) << "speedup" << std::setw(8) << "MiB" << std::setw(8) << "plan" << std::setw(7)
        << "B/TRI3" << std::setw(10) << "roofline" << std::setw(7) << "frac" << std::setw(13) << "no-account"
        << std::setw(9) << "account" << "\n";
  }
  // The rows: each Table 2 size, then the smallest one refined 1 … refine_rows times
  // (h_ave halves with each level).
  std::vector<std::pair<double, int>> rows;
  for (double h : o.sizes) rows.push_back({h, 0});
  if (!o.sizes.empty())
    for (int k = 1; k <= o.refine_rows; ++k)
      rows.push_back({*std::min_element(o.sizes.begin(), o.sizes.end()), k});
  std::vector<std::pair<double, double>> fit_points;  // (TRI3, ms/step)
  for (const auto& [h_mesh, refine] : rows) {
    const double h = std::ldexp(h_mesh, -refine);
    const std::string dir = (std::filesystem::temp_directory_path() / "fdem-bench").string();
    std::ostringstream size, skin, levels;
    size << std::setprecision(17) << "mesh.size=" << gmsh_size(h_mesh);
    skin << std::setprecision(6) << "contact.skin=" << 0.15e-3 * h;
    levels << "mesh.refine=" << refine;
    // Table 2's Δt, halved with each level of refinement (the elements' size halves).
    const double dt = std::ldexp(0.5e-9, -refine);
    std::ostringstream dt_key;
    dt_key << std::setprecision(17) << "time.dt=" << dt;
    std::vector<std::string> keys{size.str(), levels.str(), dt_key.str(), "output.dir=\"" + dir + "\"",
                                  "contact.activation=\"all\"", "contact.rebuild=\"skin\"", skin.str()};
    keys.insert(keys.end(), o.overrides.begin(), o.overrides.end());
    const PreparedCase p = prepare_case(o.case_path, keys);
    // The step time with the energy account and without it, in the same process: the
    // account's per-step totals (reactions, damping, viscous work) and its energy rows are
    // what it costs. A row every 100 steps: denser than any case's history (the cases
    // write a row every 200 to 6,000 steps). Until this round the bench took a row every
    // (steps + warm-up)/1000 steps, which for its own 1,020 steps was every step.
    auto time_steps = [&](bool account) {
      Solver solver(timed, p.model, dt, account);
      const long row = kBenchRowEvery;
      for (long s = 0; s < o.warmup; ++s) solver.step(account && (s + 1) % row == 0);
      timed.finish();
      const auto start = std::chrono::steady_clock::now();
      for (long s = 0; s < o.steps; ++s) solver.step(account && (o.warmup + s + 1) % row == 0);
      timed.finish();
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    const double seconds = time_steps(true);
    const double seconds_without = time_steps(false);
    const size_t before_bytes = cl.device_bytes_in_use();
    Solver solver(cl, p.model, dt);
    for (long s = 0; s < o.warmup; ++s) solver.step();
    cl.collect_profile();
    const auto before = cl.profile();
    const long rebuilds_before = solver.contact_rebuilds();
    for (long s = 0; s < o.steps; ++s) solver.step();
    cl.collect_profile();
    const double ms = 1e3 * seconds / o.steps;
    const double ms_without = 1e3 * seconds_without / o.steps;
    const size_t couples = solver.contact_candidates(), touching = solver.contact_touching();
    const long rebuilds = solver.contact_rebuilds() - rebuilds_before;
    const double bytes = bytes_per_step(p.model, couples, touching);
    const double roofline = bandwidth > 0 ? 1e3 * bytes / bandwidth : 0;
    fit_points.push_back({static_cast<double>(p.model.num_triangles()), ms});
    const auto paper = refine == 0 && kPaper.count(h) ? kPaper.at(h) : std::pair<long, double>{0, 0};
    const double paper_ms = paper.second / 10.0;
    // Device memory this model holds after the run: what its arrays, stages and contact
    // lists (grown as needed) took; and what Solver::plan says it needs at the start
    // (lists at their first capacity, plus the largest transient array).
    const double used = static_cast<double>(cl.device_bytes_in_use() - before_bytes);
    const double planned_mib = static_cast<double>(Solver::bytes_needed(p.model, cl.group_size())) / 1048576.0;
    const double mib = used / 1048576.0, per_tri = used / std::max<size_t>(p.model.num_triangles(), 1);
    out << std::fixed << std::setw(6) << std::setprecision(2) << h << std::setw(10) << p.model.num_triangles()
        << std::setw(10) << p.model.ce4.size() << std::setw(10) << p.model.num_nodes() << std::setw(11) << couples
        << std::setw(9) << touching << std::setw(6) << rebuilds << std::setw(11) << std::setprecision(3) << ms
        << std::setw(9) << std::setprecision(2) << paper_ms << std::setw(9) << std::setprecision(1)
        << (paper_ms > 0 ? paper_ms / ms : 0) << std::setw(8) << std::setprecision(0) << mib << std::setw(8)
        << planned_mib << std::setw(7)
        << per_tri << std::setw(10) << std::setprecision(3) << roofline << std::setw(7) << std::setprecision(3)
        << (roofline > 0 ? roofline / ms : 0) << std::setw(13) << ms_without << std::setw(8) << std::setprecision(1)
        << 100.0 * (ms - ms_without) / ms_without << "%" << std::defaultfloat << "\n";
    for (const auto& [name, t] : cl.profile()) {
      const auto it = before.find(name);
      const double spent = t.seconds - (it == before.end() ? 0 : it->second.seconds);
      const long launches = t.launches - (it == before.end() ? 0 : it->second.launches);
      if (spent > 0)
        out << "        " << std::left << std::setw(58) << name << std::right << std::fixed << std::setprecision(4)
            << 1e3 * spent / o.steps << " ms/step  (" << launches << " launches)\n" << std::defaultfloat;
    }
    csv << h << "," << p.model.num_triangles() << "," << p.model.ce4.size() << "," << p.model.num_nodes() << ","
        << couples << "," << touching << "," << rebuilds << "," << ms << "," << paper_ms << ","
        << (paper_ms > 0 ? paper_ms / ms : 0) << "," << mib << "," << per_tri << "," << roofline << ","
        << (roofline > 0 ? roofline / ms : 0) << "," << ms_without << "," << planned_mib << "\n";
  }
  double fit_a = 0, fit_b = 0;  // the intact rows' line, ms/step = a + b · TRI3
  if (fit_points.size() >= 2) {
    // Least-squares line ms = a + b · TRI3 over the rows, and each row's distance from it:
    // a cost linear in the model size shows as small distances at the large rows.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(fit_points.size());
    for (const auto& [x, y] : fit_points) sx += x, sy += y, sxx += x * x, sxy += x * y;
    const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx), a = (sy - b * sx) / n;
    fit_a = a, fit_b = b;
    out << std::setprecision(4) << "linear fit over the rows: ms/step = " << a << " + " << b * 1e6
        << " × (TRI3 / 1e6); each row's ms/step against the fit:";
    for (const auto& [x, y] : fit_points) out << " " << std::setprecision(3) << 100.0 * (y / (a + b * x) - 1) << "%";
    out << std::defaultfloat << "\n";
  }
  if (!o.fracturing.empty()) {
    out << "fracturing rows: each case as `fdem run` steps it (its own dt, activation, skin, loads; no output, an\n"
           "energy row every " << kBenchRowEvery << " steps) on a plain queue; det/1k: contact detections per 1,000\n"
           "steps; skin: the skins it used [mm] (\"auto\": picked at each detection); ms/det: one detection of the\n"
           "broken model (host clock, mean of 20); intact: the intact rows' line at the same TRI3 (ns per TRI3-step),\n"
           "x: this row against it\n";
    out << std::setw(12) << "row" << std::setw(10) << "TRI3" << std::setw(9) << "steps" << std::setw(10) << "ms/step"
        << std::setw(9) << "steps/s" << std::setw(8) << "det/1k" << std::setw(14) << "skin" << std::setw(8)
        << "ms/det" << std::setw(8) << "broken" << std::setw(9) << "ns/TRI3" << std::setw(8) << "intact" << std::setw(7)
        << "x" << std::setw(8) << "MiB" << std::setw(8) << "plan" << std::setw(8) << "B/TRI3" << "\n";
    csv << "\nrow,tri3,ce4,steps,ms_per_step,steps_per_s,detections_per_1000,skin_min_mm,skin_max_mm,ms_per_detection,"
           "broken_ce4,ns_per_tri3_step,intact_ns_per_tri3_step,device_mib,planned_mib,bytes_per_tri3\n";
    for (const std::string& name : o.fracturing) {
      const FracturingRow row = fracturing_row(name, o);
      const FracturingResult r = run_fracturing(row, o.overrides, timed);
      const double steps = static_cast<double>(std::max<long>(r.steps, 1)), tri3 = static_cast<double>(r.tri3);
      const double ms = 1e3 * r.seconds / steps, ns = 1e6 * ms / tri3;
      const double intact = fit_b > 0 ? 1e6 * (fit_a + fit_b * tri3) / tri3 : 0;
      const double mib = r.used_bytes / 1048576.0, plan = r.planned_bytes / 1048576.0, per_tri = r.used_bytes / tri3;
      out << std::fixed << std::setw(12) << name << std::setw(10) << r.tri3 << std::setw(9) << r.steps << std::setw(10)
          << std::setprecision(3) << ms << std::setw(9) << std::setprecision(0) << 1e3 / ms << std::setw(8)
          << std::setprecision(1) << 1e3 * r.detections / steps << std::setw(14) << skin_range(r.skin_lo, r.skin_hi)
          << std::setw(8) << std::setprecision(3) << r.ms_per_detection << std::setw(8) << r.broken << std::setw(9)
          << std::setprecision(2) << ns << std::setw(8) << intact << std::setw(7) << (intact > 0 ? ns / intact : 0)
          << std::setw(8) << std::setprecision(0) << mib << std::setw(8) << plan << std::setw(8) << per_tri
          << std::defaultfloat << "\n";
      csv << name << "," << r.tri3 << "," << r.ce4 << "," << r.steps << "," << ms << "," << 1e3 / ms << ","
          << 1e3 * r.detections / steps << "," << 1e3 * r.skin_lo << "," << 1e3 * r.skin_hi << "," << r.ms_per_detection << ","
          << r.broken << "," << ns << "," << intact << "," << mib << "," << plan << "," << per_tri << "\n";
    }
  }
  if (!o.fluid.empty()) {
    out << "fluid rows: cases/kgd/viscosity.toml (mesh.refine K for kgd:K) over its first " << o.fluid_window
        << " s as `fdem run` steps it\n(no output, an energy row every " << kBenchRowEvery
        << " steps), then the same model and steps without its [fluid] stage; +fluid: what the fluid adds\n";
    out << std::setw(8) << "row" << std::setw(9) << "TRI3" << std::setw(9) << "CE4" << std::setw(10) << "vertices"
        << std::setw(8) << "steps" << std::setw(5) << "sub" << std::setw(11) << "ms/step" << std::setw(11) << "no fluid"
        << std::setw(9) << "+fluid" << std::setw(8) << "broken" << "\n";
    csv << "\nrow,tri3,ce4,vertices,steps,substeps,ms_per_step,ms_per_step_without_fluid,fluid_share,broken_ce4\n";
    for (const std::string& name : o.fluid) {
      const int refine = name.size() == 5 ? name[4] - '0' : 0;
      const FluidResult r = run_fluid_row(refine, o.fluid_window, o, timed);
      const double steps = static_cast<double>(r.steps);
      const double ms = 1e3 * r.seconds / steps, ms_without = 1e3 * r.seconds_without / steps;
      out << std::fixed << std::setw(8) << name << std::setw(9) << r.tri3 << std::setw(9) << r.ce4 << std::setw(10)
          << r.vertices << std::setw(8) << r.steps << std::setw(5) << r.substeps << std::setw(11) << std::setprecision(4)
          << ms << std::setw(11) << ms_without << std::setw(8) << std::setprecision(1)
          << 100.0 * (ms - ms_without) / ms_without << "%" << std::setw(8) << r.broken << std::defaultfloat << "\n";
      csv << name << "," << r.tri3 << "," << r.ce4 << "," << r.vertices << "," << r.steps << "," << r.substeps << ","
          << ms << "," << ms_without << "," << (ms - ms_without) / ms_without << "," << r.broken << "\n";
    }
  }
  if (!o.csv.empty()) {
    std::ofstream file(o.csv);
    if (!(file << csv.str())) throw OutputError("cannot write " + o.csv);
    out << "wrote " << o.csv << "\n";
  }
  return 0;
}

}  // namespace fdem
