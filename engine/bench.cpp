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

}  // namespace

int run_bench(const BenchOptions& o, const std::string& device, std::ostream& out) {
  // Two queues on the device: the step time is taken on a plain one (profiling events
  // cost host time per launch), the per-stage breakdown on a profiling one.
  ClContext timed(device, false);
  ClContext cl(device, true);
  const double bandwidth = cl.info().is_gpu ? 4.3e12 : 0.0;  // H200 figure; no CPU bound printed
  std::ostringstream csv;
  csv << "h_ave_mm,tri3,ce4,nodes,initial_couples,touching,rebuilds,ms_per_step,paper_ms_per_step,speedup,"
         "device_mib,bytes_per_tri3,roofline_ms,roofline_fraction,ms_per_step_without_account,planned_mib\n";
  out << "fdem bench on " << cl.description() << ": " << o.warmup << " warm-up + " << o.steps
      << " timed steps, dt 0.5 ns (halved per mesh.refine level), activation \"all\", skin 0.15 h_ave (rebuild when exceeded);\n"
      << "ms/step on a plain queue with the energy account (a row every " << kBenchRowEvery
      << " steps), no-account without it (same process); the stage times below from a run on a profiling queue\n";
  out << std::setw(6) << "h_ave" << std::setw(10) << "TRI3" << std::setw(10) << "CE4" << std::setw(10) << "nodes"
      << std::setw(11) << "couples" << std::setw(9) << "touch" << std::setw(6) << "rebd" << std::setw(11)
      << "ms/step" << std::setw(9) << "GP100" << std::setw(9) << "speedup" << std::setw(8) << "MiB" << std::setw(8) << "plan" << std::setw(7)
      << "B/TRI3" << std::setw(10) << "roofline" << std::setw(7) << "frac" << std::setw(13) << "no-account"
      << std::setw(9) << "account" << "\n";
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
    const PreparedCase p = prepare_case(o.case_path, {size.str(), levels.str(), dt_key.str(),
                                                      "output.dir=\"" + dir + "\"", "contact.activation=\"all\"",
                                                      "contact.rebuild=\"skin\"", skin.str()});
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
  if (fit_points.size() >= 2) {
    // Least-squares line ms = a + b · TRI3 over the rows, and each row's distance from it:
    // a cost linear in the model size shows as small distances at the large rows.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(fit_points.size());
    for (const auto& [x, y] : fit_points) sx += x, sy += y, sxx += x * x, sxy += x * y;
    const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx), a = (sy - b * sx) / n;
    out << std::setprecision(4) << "linear fit over the rows: ms/step = " << a << " + " << b * 1e6
        << " × (TRI3 / 1e6); each row's ms/step against the fit:";
    for (const auto& [x, y] : fit_points) out << " " << std::setprecision(3) << 100.0 * (y / (a + b * x) - 1) << "%";
    out << std::defaultfloat << "\n";
  }
  if (!o.csv.empty()) {
    std::ofstream file(o.csv);
    if (!(file << csv.str())) throw OutputError("cannot write " + o.csv);
    out << "wrote " << o.csv << "\n";
  }
  return 0;
}

}  // namespace fdem
