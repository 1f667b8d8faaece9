#include "engine/bench.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>

#include "engine/device_arrays.hpp"
#include "engine/errors.hpp"
#include "engine/run.hpp"
#include "engine/solver.hpp"

namespace fdem {

namespace {

// Table 2 of the seed paper: h_ave [mm] → (TRI3, Quadro GP100 seconds per 10,000 steps).
const std::map<double, std::pair<long, double>> kPaper = {
    {0.6, {60346, 126}}, {0.5, {86570, 134}}, {0.4, {136774, 146}},
    {0.3, {241298, 214}}, {0.2, {540754, 392}}, {0.15, {1084398, 846}}};

// Bytes one step must move at least: node state read and written, element, CE4 and
// couple data read once (the bound printed as "roofline"; H200 about 4.3 TB/s).
double bytes_per_step(const Model& m, size_t couples) {
  const double r = sizeof(real);
  const double nodes = m.num_nodes() * (2 * r * 2 * 2 + 2 * r * 2 + 4);          // x, v read+write; f, mass read; group
  const double tris = m.num_triangles() * (12 + 4 * r + 4 + 3 * 2 * r * 2 + 3 * 2 * r);  // nodes, X⁻¹, material, x+v gathers, corner forces
  const double ce4 = m.ce4.size() * (16 + 12 * r + 2 * 12 * r + 8 + 4 * 2 * r * 2);       // nodes, params, state r/w, status, x gathers + slots
  const double contact = couples * (8 + 2 * 10 * r + 6 * 2 * r * 2 + 6 * 16);            // key, history r/w, x+v gathers, atomics
  return nodes + tris + ce4 + contact;
}

}  // namespace

int run_bench(const BenchOptions& o, ClContext& cl, std::ostream& out) {
  if (!cl.profiling()) throw DeviceError("fdem bench needs a profiling queue");
  const double bandwidth = cl.info().is_gpu ? 4.3e12 : 0.0;  // H200 figure; no CPU bound printed
  std::ostringstream csv;
  csv << "h_ave_mm,tri3,ce4,nodes,initial_couples,ms_per_step,paper_ms_per_step,speedup,device_mib,roofline_ms,"
         "roofline_fraction\n";
  out << "fdem bench on " << cl.description() << ": " << o.warmup << " warm-up + " << o.steps
      << " timed steps, dt 0.5 ns, activation \"all\"\n";
  out << std::setw(6) << "h_ave" << std::setw(10) << "TRI3" << std::setw(10) << "CE4" << std::setw(10) << "nodes"
      << std::setw(11) << "couples" << std::setw(11) << "ms/step" << std::setw(11) << "GP100" << std::setw(9)
      << "speedup" << std::setw(9) << "MiB" << std::setw(11) << "roofline" << std::setw(8) << "frac" << "\n";
  for (double h : o.sizes) {
    const std::string dir = (std::filesystem::temp_directory_path() / "fdem-bench").string();
    std::ostringstream size, steps;
    size << std::setprecision(6) << "mesh.size=" << 0.85e-3 * h;  // gmsh size ≈ 0.85 h_ave (io-notes)
    steps << "time.steps=" << o.warmup + o.steps;
    const PreparedCase p = prepare_case(o.case_path, {size.str(), "time.dt=0.5e-9", "output.dir=\"" + dir + "\"",
                                                      "contact.activation=\"all\"", "contact.rebuild=\"step\""});
    Solver solver(cl, p.model, 0.5e-9);
    for (long s = 0; s < o.warmup; ++s) solver.step();
    cl.collect_profile();
    const auto before = cl.profile();
    const auto start = std::chrono::steady_clock::now();
    for (long s = 0; s < o.steps; ++s) solver.step();
    cl.finish();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cl.collect_profile();
    const double ms = 1e3 * seconds / o.steps;
    const size_t couples = solver.contact_candidates();
    const double bytes = bytes_per_step(p.model, couples);
    const double roofline = bandwidth > 0 ? 1e3 * bytes / bandwidth : 0;
    const auto paper = kPaper.count(h) ? kPaper.at(h) : std::pair<long, double>{0, 0};
    const double paper_ms = paper.second / 10.0;
    const double mib = DeviceArrays::bytes_needed(p.model) / 1048576.0;
    out << std::fixed << std::setw(6) << std::setprecision(2) << h << std::setw(10) << p.model.num_triangles()
        << std::setw(10) << p.model.ce4.size() << std::setw(10) << p.model.num_nodes() << std::setw(11) << couples
        << std::setw(11) << std::setprecision(3) << ms << std::setw(11) << paper_ms << std::setw(9)
        << std::setprecision(1) << (paper_ms > 0 ? paper_ms / ms : 0) << std::setw(9) << std::setprecision(0) << mib
        << std::setw(11) << std::setprecision(3) << roofline << std::setw(8) << std::setprecision(3)
        << (roofline > 0 ? roofline / ms : 0) << std::defaultfloat << "\n";
    for (const auto& [name, t] : cl.profile()) {
      const auto it = before.find(name);
      const double spent = t.seconds - (it == before.end() ? 0 : it->second.seconds);
      if (spent > 0) out << "        " << std::left << std::setw(58) << name << std::right << std::fixed
                         << std::setprecision(4) << 1e3 * spent / o.steps << " ms/step\n" << std::defaultfloat;
    }
    csv << h << "," << p.model.num_triangles() << "," << p.model.ce4.size() << "," << p.model.num_nodes() << ","
        << couples << "," << ms << "," << paper_ms << "," << (paper_ms > 0 ? paper_ms / ms : 0) << "," << mib << ","
        << roofline << "," << (roofline > 0 ? roofline / ms : 0) << "\n";
  }
  if (!o.csv.empty()) {
    std::ofstream file(o.csv);
    if (!(file << csv.str())) throw OutputError("cannot write " + o.csv);
    out << "wrote " << o.csv << "\n";
  }
  return 0;
}

}  // namespace fdem
