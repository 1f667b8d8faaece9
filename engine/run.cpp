#include "engine/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <unistd.h>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <cstdint>
#include <csignal>
#include <map>
#include <ostream>
#include <sstream>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/checkpoint_identity.hpp"
#include "engine/fracture_events.hpp"
#include "engine/history.hpp"
#include "engine/solver.hpp"
#include "engine/fragments.hpp"
#include "engine/scale_out.hpp"
#include "io/exodus_writer.hpp"
#include "io/fragment_writer.hpp"
#include "io/gmsh_reader.hpp"
#include "io/checkpoint_file.hpp"
#include "io/events_writer.hpp"
#include "io/history_writer.hpp"
#include "io/output_resume.hpp"
#include <functional>

namespace fdem {

namespace fs = std::filesystem;

namespace {

// How old the history file's last sync may get before a row syncs it (HistoryWriter): the
// rows a killed run can lose, beyond those after its last checkpoint or frame.
constexpr double kHistorySyncSeconds = 0.5;

// Steps (1-based step counts, step 0 = initial state) at which frames are written.
std::vector<long> frame_steps(const io::OutputConfig& out, long steps, double dt) {
  std::vector<long> list;
  if (out.every > 0) {
    const long stride = std::max(1L, std::lround(out.every / dt));
    for (long s = 0; s < steps; s += stride) list.push_back(s);
    list.push_back(steps);
  } else {
    const int frames = out.frames > 0 ? out.frames : 20;
    if (frames == 1) return {steps};
    for (int k = 0; k < frames; ++k) list.push_back(std::lround(double(k) * steps / (frames - 1)));
  }
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
  return list;
}

std::vector<std::string> element_names(const Model& model) {
  std::vector<std::string> names = {"SXX", "SYY", "SXY", "PS1", "PS2"};
  if (!model.ce4.empty()) names.insert(names.end(), {"DAMAGE", "BROKEN", "MODE", "OPENING", "SLIP", "FRAGMENT"});
  return names;
}

std::vector<std::string> nodal_names(const Model& model) {
  std::vector<std::string> names = {"DISPLX", "DISPLY", "VELX", "VELY"};
  if (model.contact.enabled) names.insert(names.end(), {"CONTACT_FX", "CONTACT_FY"});
  return names;
}

// One frame's values of the whole model, in global order: read from the solver, or in a
// split run gathered to rank 0 (empty on the other ranks).
struct FrameData {
  std::vector<real2> x, v, contact_force;
  std::vector<real4> stress;
  std::vector<real> damage, opening, slip;
  std::vector<int> broken, mode, labels;
};

// Reads the current state for a frame; `stress_current`: the stress of this state has
// been evaluated already (a history row with probes at the same step). Collective in a
// split run.
FrameData read_frame(const Model& model, Solver& solver, SplitRun* split, bool stress_current = false) {
  if (!stress_current) solver.enqueue_stress();
  FrameData f;
  if (!split) {
    f.x = solver.positions(), f.v = solver.velocities(), f.stress = solver.stresses();
    if (model.contact.enabled) f.contact_force = solver.contact_forces();
  } else {
    f.x = split->gather(ItemKind::Node, solver.positions());
    f.v = split->gather(ItemKind::Node, solver.velocities());
    f.stress = split->gather(ItemKind::Triangle, solver.stresses());
    if (model.contact.enabled) f.contact_force = split->gather(ItemKind::Node, solver.contact_forces());
  }
  if (!model.ce4.empty()) {
    auto& ce4 = *solver.cohesive();
    if (!split) {
      f.damage = ce4.damage(), f.opening = ce4.opening(), f.slip = ce4.slip(), f.broken = ce4.broken(), f.mode = ce4.mode();
      // FRAGMENT: the pieces (FragmentLabels), reused while no CE4 broke since the last labelling.
      f.labels = solver.fragment_labels(
          static_cast<long>(std::count_if(f.broken.begin(), f.broken.end(), [](int b) { return b != 0; })));
    } else {
      f.damage = split->gather(ItemKind::Ce4, ce4.damage());
      f.opening = split->gather(ItemKind::Ce4, ce4.opening());
      f.slip = split->gather(ItemKind::Ce4, ce4.slip());
      f.broken = split->gather(ItemKind::Ce4, ce4.broken());
      f.mode = split->gather(ItemKind::Ce4, ce4.mode());
      if (split->root()) f.labels = host_fragment_labels(model, f.broken);
    }
  }
  return f;
}

// Writes a frame read by read_frame (rank 0 of a split run only).
// With CE4s, also the frame's pieces: FRAGMENT and `fragments`' records.
void write_frame(io::ExodusWriter& exo, io::FragmentWriter* fragments, const Model& model, const FrameData& f,
                 double time, ClContext& cl) {
  const auto& x = f.x;
  const auto& v = f.v;
  const auto& stress = f.stress;
  const size_t n = model.num_nodes();
  std::vector<std::vector<double>> nodal(model.contact.enabled ? 6 : 4, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    nodal[0][i] = x[i].x - model.x[i];
    nodal[1][i] = x[i].y - model.y[i];
    nodal[2][i] = v[i].x;
    nodal[3][i] = v[i].y;
  }
  if (model.contact.enabled) {
    const auto& fc = f.contact_force;
    for (size_t i = 0; i < n; ++i) nodal[4][i] = fc[i].x, nodal[5][i] = fc[i].y;
  }
  const bool fracture = !model.ce4.empty();
  std::vector<std::vector<std::vector<double>>> elem(element_names(model).size());
  for (size_t m = 0; m < model.materials.size(); ++m) {
    const size_t begin = model.block_start[m], end = model.block_start[m + 1];
    if (begin == end) continue;
    for (auto& var : elem) var.emplace_back(fracture ? end - begin : 0, 0.0);
    for (size_t t = begin; t < end; ++t) {
      const double sxx = stress[t].x, syy = stress[t].y, sxy = stress[t].z;
      const double centre = 0.5 * (sxx + syy), radius = std::hypot(0.5 * (sxx - syy), sxy);
      const double values[5] = {sxx, syy, sxy, centre + radius, centre - radius};
      for (int k = 0; k < 5; ++k) {
        if (fracture) elem[k].back()[t - begin] = values[k];
        else elem[k].back().push_back(values[k]);
      }
    }
  }
  if (fracture) {  // the cohesive block: CE4 variables, zero stresses
    const auto& damage = f.damage;
    const auto& opening = f.opening;
    const auto& slip = f.slip;
    const auto& broken = f.broken;
    const auto& mode = f.mode;
    const size_t n = model.ce4.size();
    for (auto& var : elem) var.emplace_back(n, 0.0);
    // FRAGMENT: the piece's id (Exodus element number of its first triangle) on every
    // triangle; on an intact CE4 its triangles' piece, on a broken one 0.
    const auto& labels = f.labels;
    for (size_t m = 0, b = 0; m < model.materials.size(); ++m) {
      const size_t begin = model.block_start[m], end = model.block_start[m + 1];
      if (begin == end) continue;
      for (size_t t = begin; t < end; ++t) elem[10][b][t - begin] = labels[t] + 1;
      ++b;
    }
    for (size_t e = 0; e < n; ++e) {
      elem[5].back()[e] = damage[e];
      elem[6].back()[e] = broken[e];
      elem[7].back()[e] = mode[e];
      elem[8].back()[e] = opening[e];
      elem[9].back()[e] = slip[e];
      elem[10].back()[e] = broken[e] ? 0 : labels[model.ce4_triangles[e][0]] + 1;
    }
    if (fragments) fragments->write_frame(time, summarise_fragments(model, labels, x).fragments);
  }
  const auto began = std::chrono::steady_clock::now();
  exo.write_frame(time, nodal, elem);
  if (cl.profiling())
    cl.add_host_time("Exodus frame write (host wall, incl. sync)",
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
}

std::string describe_failure(const Model& model, const Conditions& c) {
  std::ostringstream msg;
  if (c.bad_node >= 0) {
    msg << "step " << c.bad_node_step << ": node " << model.node_tags[c.bad_node] << " (at "
        << model.x[c.bad_node] << ", " << model.y[c.bad_node]
        << ") got a non-finite position or velocity; the time step may be unstable or a load too large";
  } else {
    const auto& tri = model.triangles[c.inverted_triangle];
    msg << "step " << c.inverted_step << ": triangle " << model.triangle_tags[c.inverted_triangle]
        << " (material '" << model.materials[model.triangle_material[c.inverted_triangle]].name
        << "', nodes " << model.node_tags[tri[0]] << " " << model.node_tags[tri[1]] << " "
        << model.node_tags[tri[2]] << ") inverted (J <= 0)";
  }
  return msg.str();
}


// The checkpoint's attributes with the digests of the records each file held when it was
// written (io/output_resume.hpp): what a restart checks the earlier files against.
constexpr const char* kExodusDigests = "exodus_frame_digests";
constexpr const char* kHistoryDigests = "history_row_digests";
constexpr const char* kFragmentDigests = "fragment_frame_digests";

// A run's output files, written as PATH.partial until put_in_place renames them to PATH
// (at the run's first frame or checkpoint). Until then a failed run removes them, so it
// leaves an earlier run's files at PATH as they were.
class PendingOutputs {
 public:
  static constexpr const char* kSuffix = ".partial";
  PendingOutputs() = default;
  PendingOutputs(const PendingOutputs&) = delete;
  PendingOutputs& operator=(const PendingOutputs&) = delete;
  ~PendingOutputs() {
    std::error_code ec;
    if (!placed_)
      for (const auto& path : paths_) fs::remove(path + kSuffix, ec);
  }
  void add(const std::string& path) { paths_.push_back(path); }
  bool placed() const { return placed_; }
  void put_in_place() {
    placed_ = true;
    for (const auto& path : paths_) {
      std::error_code ec;
      fs::rename(path + kSuffix, path, ec);
      if (ec) throw OutputError("cannot put " + path + kSuffix + " in place of " + path + ": " + ec.message());
    }
  }

 private:
  std::vector<std::string> paths_;
  bool placed_ = false;
};

// Folders a run must not write its files straight into: the root of the file system, the
// system's own directories (with everything below them), and the folders whose
// subfolders may hold data (/dev/shm, /usr/local/src, /var/tmp, /run/user/UID) but which
// hold none themselves. As root nothing else would stop it.
const char* const kSystemTrees[] = {"/bin",         "/boot",     "/etc",       "/lib",         "/lib32",
                                    "/lib64",       "/libx32",   "/proc",      "/sbin",        "/sys",
                                    "/usr/bin",     "/usr/include", "/usr/lib", "/usr/lib32",  "/usr/lib64",
                                    "/usr/libexec", "/usr/libx32", "/usr/sbin", "/usr/share"};
const char* const kSystemFolders[] = {"/dev", "/home", "/media", "/mnt", "/opt", "/run",
                                      "/srv", "/usr",  "/usr/local", "/usr/src", "/var"};

// InputError when output.dir is one of those, or output.name would put a file elsewhere
// than output.dir (io/case_reader checks the characters of a name; this is the backstop
// for the paths the run builds from it).
void check_output_place(const io::CaseConfig& c) {
  std::error_code ec;
  fs::path dir = fs::weakly_canonical(fs::absolute(c.output.dir, ec), ec);
  if (ec) dir = fs::absolute(c.output.dir).lexically_normal();
  std::string resolved = dir.string();
  while (resolved.size() > 1 && resolved.back() == '/') resolved.pop_back();
  const std::string key = c.path + ": output.dir = \"" + c.output.dir + "\"";
  const std::string advice = ": give the results a folder of their own (the default is \"out\", in the current directory)";
  if (resolved == "/") throw InputError(key + " is the root of the file system" + advice);
  for (const char* tree : kSystemTrees) {
    const std::string t = tree;
    if (resolved == t || resolved.rfind(t + "/", 0) == 0)
      throw InputError(key + " is " + (resolved == c.output.dir ? "" : resolved + ", ") + "in the system directory " + t + advice);
  }
  for (const char* folder : kSystemFolders)
    if (resolved == folder) throw InputError(key + " is the system directory " + resolved + advice);
  const std::string& name = c.output.name;
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
      std::any_of(name.begin(), name.end(), [](char ch) { return static_cast<unsigned char>(ch) < 0x20; }))
    throw InputError(c.path + ": output.name = \"" + name +
                     "\" is not a file name (no '/', no control characters, not . or ..): the output files go into "
                     "output.dir and nowhere else");
}

// OutputError when `dir` can neither be written (it exists) nor made (the nearest folder
// above it that exists cannot be written): what `fdem run` would meet, found before
// anything is computed, by `fdem check` as well.
void check_output_dir(const std::string& dir) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(dir, ec);
  // The folder itself, or the nearest folder above it that exists, which it is made in.
  fs::path existing = absolute;
  while (!fs::exists(existing, ec) && existing.has_relative_path()) existing = existing.parent_path();
  if (!fs::is_directory(existing, ec))
    throw OutputError("cannot create output directory '" + dir + "': '" + existing.string() + "' is not a directory");
  if (::access(existing.c_str(), W_OK | X_OK) != 0) {
    const std::string why = std::strerror(errno);
    throw OutputError(existing == absolute ? "cannot write in output directory '" + dir + "': " + why
                                           : "cannot create output directory '" + dir + "' in '" + existing.string() +
                                                 "': " + why);
  }
}

void make_output_dir(const std::string& dir) {
  check_output_dir(dir);
  try {
    fs::create_directories(dir);
  } catch (const fs::filesystem_error& e) {
    throw OutputError("cannot create output directory '" + dir + "': " + e.what());
  }
}

}  // namespace

void check_output(const PreparedCase& p) {
  check_output_dir(p.config.output.dir);
  std::error_code ec;
  // A file the run would write, taken by something else (a folder, a FIFO, a device).
  std::vector<std::string> files = {p.exodus_path, p.history_path, checkpoint_path(p)};
  if (!p.model.ce4.empty()) files.insert(files.end(), {p.fragments_path, p.events_path});
  for (const auto& file : files) {
    const auto status = fs::status(file, ec);
    if (!ec && fs::exists(status) && !fs::is_regular_file(status))
      throw OutputError("output file '" + file + "' exists and is not a regular file: move it away or choose another "
                        "output.dir or output.name");
  }
}

std::string checkpoint_path(const PreparedCase& p) {
  return (fs::path(p.config.output.dir) / (p.config.output.name + ".ckpt")).string();
}

PreparedCase prepare_case(const std::string& case_path, const std::vector<std::string>& overrides) {
  PreparedCase p;
  p.config = io::read_case(case_path, overrides);
  auto& c = p.config;
  if (c.output.name.empty()) c.output.name = fs::path(case_path).stem().string();
  check_output_place(c);

  std::string mesh_path = c.mesh.file;
  if (!c.mesh.geo.empty()) {
    make_output_dir(c.output.dir);
    // Meshes made from .geo files are cached in FDEM_MESH_CACHE when set (shared across
    // runs and machines), else next to the output.
    const char* cache = std::getenv("FDEM_MESH_CACHE");
    mesh_path = io::mesh_geo(c.mesh.geo, c.mesh.size, c.mesh.algorithm, cache && *cache ? cache : c.output.dir, io::geo_meshing());
  }
  const io::Mesh mesh = io::read_gmsh(mesh_path, &p.notes);
  p.model = build_model(mesh, c, p.notes);
  p.stable = stable_time_step(p.model);
  p.probes = locate_probes(p.model, c.probes, c.path);

  if (p.model.mass_scaling && p.model.contact.enabled)
    throw InputError(c.path + ": [damping] mass_scaling does not account for contact springs, so the step would be "
                     "unstable; relax a contact case with local damping on true masses (mass_scaling = false, dt = \"auto\")");
  if (c.time.dt_auto) {
    p.dt = c.time.safety * p.stable.dt;
  } else {
    p.dt = c.time.dt;
    if (!p.model.mass_scaling && p.dt > p.stable.dt) {
      const size_t t = p.stable.triangle;
      throw InputError(c.path + ": time.dt = " + format_number(p.dt) + " s exceeds the stable estimate " +
                       format_number(p.stable.dt) + " s (set by triangle " + std::to_string(p.model.triangle_tags[t]) +
                       " of material '" + p.model.materials[p.model.triangle_material[t]].name +
                       "'). Use dt = \"auto\", a dt below the estimate, or [damping] mass_scaling = true for a static run.");
    }
  }
  p.steps = io::run_steps(c, p.dt);
  // A checkpoint is written after a step: a shorter interval cannot be kept, and the
  // schedule is reckoned in steps of dt.
  if (c.output.checkpoint_every > 0 && c.output.checkpoint_every < p.dt)
    throw InputError(c.path + ": output.checkpoint_every = " + format_number(c.output.checkpoint_every) +
                     " s is shorter than the time step dt = " + format_number(p.dt) +
                     " s (a checkpoint is written after a step): give at least dt, or 0 for one at the end of the run only");
  p.exodus_path = (fs::path(c.output.dir) / (c.output.name + ".exo")).string();
  p.history_path = (fs::path(c.output.dir) / (c.output.name + "_history.nc")).string();
  p.fragments_path = (fs::path(c.output.dir) / (c.output.name + "_fragments.nc")).string();
  p.events_path = (fs::path(c.output.dir) / (c.output.name + "_events.nc")).string();
  return p;
}

RunSummary run_case(const PreparedCase& p, ClContext& cl, std::ostream& log, bool status_line,
                    const RunOptions& options) {
  const Model& model = p.model;
  const auto& config = p.config;
  // Before anything is computed: the folder and the file names the run will write.
  auto make_output = [&] {
    check_output(p);
    make_output_dir(config.output.dir);
  };

  // A split run (mpirun -np N, N > 1): this rank's share of the model, its Solver, the
  // ghost exchange. Every rank finds the same start-up errors, or agrees on the first.
  Transport* const transport = options.transport && options.transport->size() > 1 ? options.transport : nullptr;
  std::unique_ptr<SplitRun> split;
  std::unique_ptr<Solver> solver_holder;
  if (transport) {
    std::exception_ptr failure;
    try {
      make_output();
      split = std::make_unique<SplitRun>(model, *transport, options.partition, options.contact_travel);
      solver_holder = std::make_unique<Solver>(cl, split->local_model(), p.dt);
      split->attach(cl, *solver_holder);
    } catch (...) {
      failure = std::current_exception();
    }
    agree(*transport, failure);
  } else {
    make_output();
    solver_holder = std::make_unique<Solver>(cl, model, p.dt);
  }
  Solver& solver = *solver_holder;
  const bool root = !split || split->root();
  RunSummary summary;
  const bool resumed = !options.restart.empty();
  // A resumed run: the digests of the records each file held at the checkpoint, by the
  // checkpoint's attribute (io/output_resume.hpp).
  std::map<std::string, std::vector<std::uint64_t>> earlier_records;
  if (resumed) {
    // Every rank of a split run reads the (whole-model) checkpoint and takes its share;
    // they find the same problems with it, or agree on the first.
    io::CheckpointData data;
    std::exception_ptr failure;
    try {
      data = io::read_checkpoint_file(options.restart);
      check_fits(data, p, options.restart);
      std::vector<const char*> keys = {kExodusDigests, kHistoryDigests};
      if (!model.ce4.empty()) keys.push_back(kFragmentDigests);
      for (const char* key : keys) {
        const auto it = data.text.find(key);
        try {
          if (it == data.text.end()) throw std::invalid_argument("missing");
          earlier_records[key] = io::parse_digests(it->second);
        } catch (const std::invalid_argument&) {
          throw InputError("checkpoint '" + options.restart + "' has no readable '" + key + "' attribute");
        }
      }
      const io::CheckpointData local = split ? split->local_state(data) : io::CheckpointData();
      StateReader in(cl, split ? local : data, options.restart);
      solver.load_state(in);
      if (solver.steps_done() >= p.steps)
        throw InputError("checkpoint '" + options.restart + "' is at step " + std::to_string(solver.steps_done()) +
                         " (t = " + format_number(solver.time()) + " s), and the case ends at step " +
                         std::to_string(p.steps) + ": extend the run with --set time.end=...");
    } catch (...) {
      if (!transport) throw;
      failure = std::current_exception();
    }
    if (transport) agree(*transport, failure);
    summary.worst_energy_error = data.numbers.count("worst_energy_error") ? data.numbers.at("worst_energy_error") : 0;
    summary.first_step = solver.steps_done();
    (options.info ? *options.info : log) << "resumed from " << options.restart << " at step " << solver.steps_done()
                                         << ", t = " << format_number(solver.time(), 10) << " s\n" << std::flush;
  }

  std::vector<io::ExodusBlock> blocks;
  for (size_t m = 0; m < model.materials.size(); ++m) {
    io::ExodusBlock block{model.materials[m].name, "TRI3", 3, {}};
    for (size_t t = model.block_start[m]; t < model.block_start[m + 1]; ++t)
      block.connectivity.insert(block.connectivity.end(), model.triangles[t].begin(), model.triangles[t].end());
    if (!block.connectivity.empty()) blocks.push_back(std::move(block));
  }
  if (!model.ce4.empty()) {
    // Nodes (i, j, j', i'): a zero-area quadrilateral that opens as the crack does.
    io::ExodusBlock block{"cohesive", "QUAD4", 4, {}};
    for (const auto& c : model.ce4) block.connectivity.insert(block.connectivity.end(), c.begin(), c.end());
    blocks.push_back(std::move(block));
  }
  // A run writes its files under temporary names beside the earlier run's (a resumed run
  // first copies what those hold up to the checkpoint) and puts them in place at its
  // first frame or checkpoint: the files at the final paths are whole at every moment,
  // and a run that fails before (a device or output error) leaves the earlier ones as
  // they were (PendingOutputs).
  PendingOutputs pending;
  const std::string suffix = PendingOutputs::kSuffix;
  // The files: rank 0 of a split run writes them all (the others hold none).
  const PointProbes points(p.probes);
  const std::vector<real2> masses = split ? split->gather(ItemKind::Node, solver.masses()) : solver.masses();
  std::unique_ptr<io::ExodusWriter> exodus_file;
  std::unique_ptr<HistoryTable> table_holder;
  std::unique_ptr<io::HistoryWriter> history_file;
  std::unique_ptr<io::FragmentWriter> fragments;
  std::unique_ptr<io::EventsWriter> events;
  {
    std::exception_ptr failure;
    try {
      if (root) {
        pending.add(p.exodus_path);
        pending.add(p.history_path);
        if (!model.ce4.empty()) pending.add(p.fragments_path), pending.add(p.events_path);
        exodus_file = std::make_unique<io::ExodusWriter>(p.exodus_path + suffix, config.title, model.x, model.y, blocks,
                                                         nodal_names(model), element_names(model),
                                                         io::ExodusOptions{config.output.float_frames, config.output.compress});
        table_holder = std::make_unique<HistoryTable>(model, masses, points);
        history_file = std::make_unique<io::HistoryWriter>(p.history_path + suffix, config.title, table_holder->variables());
        // Rows sync at most every kHistorySyncSeconds, and always before a frame or a
        // checkpoint: a killed run keeps every row up to its last checkpoint, which is
        // what a restart continues from (docs/case-format.md, "history").
        history_file->set_sync_interval(kHistorySyncSeconds);
        if (!model.ce4.empty()) fragments = std::make_unique<io::FragmentWriter>(p.fragments_path + suffix, config.title);
        if (!model.ce4.empty()) events = std::make_unique<io::EventsWriter>(p.events_path + suffix, config.title);
      }
    } catch (...) {
      failure = std::current_exception();
    }
    if (transport) agree(*transport, failure);
    else if (failure) std::rethrow_exception(failure);
  }

  // The break catalogue (models with CE4s): appended with the history rows; a resumed run
  // starts its file from the catalogue its checkpoint carries, so breaks written after
  // the checkpoint before a crash are dropped like rows and frames.
  CohesiveForces* const ce4 = solver.cohesive();
  std::vector<io::BreakRecord> split_catalogue;  // rank 0 of a split run: every break so far
  auto with_triangles = [&](std::vector<io::BreakRecord> records) {
    for (auto& b : records) b.tri_a = model.ce4_triangles[b.ce4][0], b.tri_b = model.ce4_triangles[b.ce4][1];
    return records;
  };
  auto record_breaks = [&]() {
    if (!ce4) return;
    const auto began = std::chrono::steady_clock::now();
    if (split) {
      const auto fresh = split->drain_breaks(*ce4);
      split_catalogue.insert(split_catalogue.end(), fresh.begin(), fresh.end());
      if (events) events->append(with_triangles(fresh));
    } else {
      events->append(with_triangles(ce4->drain_breaks()));
    }
    if (cl.profiling())
      cl.add_host_time("break catalogue (host wall: count and records read, sort, events file append)",
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
  };
  if (ce4 && !split) events->append(with_triangles(ce4->catalogue()));
  if (ce4 && split) {  // a resumed split run: the whole catalogue its checkpoint carries
    split_catalogue = split->catalogue(*ce4);
    if (events) events->append(with_triangles(split_catalogue));
  }

  const std::vector<long> frames = frame_steps(config.output, p.steps, p.dt);
  const long history_stride =
      config.output.history_every > 0 ? std::max(1L, std::lround(config.output.history_every / p.dt))
                                      : std::max(1L, p.steps / 1000);
  // Renames the files into place, once (rank 0 of a split run; the others hold none).
  auto place_outputs = [&] {
    if (!root || pending.placed()) return;
    pending.put_in_place();
    exodus_file->moved_to(p.exodus_path);
    history_file->moved_to(p.history_path);
    if (fragments) fragments->moved_to(p.fragments_path);
    if (events) events->moved_to(p.events_path);
  };
  if (resumed) {
    // What the earlier run wrote up to the checkpoint, as far as this run's schedule has
    // it: the row and frame a run writes at its own last step are not on the schedule of
    // the longer run that continues it, so a chain of runs gives the same files as one.
    // Each record is checked against the checkpoint first; an earlier file that is not
    // there is started anew at the checkpoint's step (the way on from a damaged one).
    auto step_of = [&](double t) { return std::lround(t / p.dt); };
    auto on_frames = [&](double t) { return std::binary_search(frames.begin(), frames.end(), step_of(t)); };
    auto on_rows = [&](double t) { return step_of(t) % history_stride == 0; };
    // A signal while a long copy goes: stop with the checkpoint as it is (one process;
    // the ranks of a split run stop together in the steps that follow).
    auto stopped = [&] { return !split && options.stop && *options.stop != 0; };
    bool interrupted = false;
    std::exception_ptr failure;
    try {
      auto resume = [&](const std::string& path, const char* key, auto copy_file) {
        if (interrupted) return;
        if (!fs::exists(path)) {
          (options.info ? *options.info : log)
              << "note: there is no earlier " << path << ": the new one starts at the checkpoint's step "
              << solver.steps_done() << " (t = " << format_number(solver.time()) << " s)\n";
          return;
        }
        const io::ResumeCopy copy{earlier_records.at(key), key == kHistoryDigests ? std::function<bool(double)>(on_rows)
                                                                                   : std::function<bool(double)>(on_frames),
                                  stopped};
        interrupted = copy_file(path, copy) < 0;
      };
      if (root) {
        resume(p.exodus_path, kExodusDigests,
               [&](const std::string& path, const io::ResumeCopy& c) { return io::copy_exodus_frames(path, *exodus_file, c); });
        resume(p.history_path, kHistoryDigests,
               [&](const std::string& path, const io::ResumeCopy& c) { return io::copy_history_rows(path, *history_file, c); });
        if (fragments)
          resume(p.fragments_path, kFragmentDigests, [&](const std::string& path, const io::ResumeCopy& c) {
            return io::copy_fragment_frames(path, *fragments, c);
          });
      }
    } catch (...) {
      failure = std::current_exception();
    }
    if (transport) agree(*transport, failure);
    else if (failure) std::rethrow_exception(failure);
    if (interrupted) {
      // The earlier files and the checkpoint are as they were: the same command resumes.
      const int signal = static_cast<int>(*options.stop);
      summary.interrupted = true;
      summary.stop_reason = signal == SIGTERM ? "SIGTERM" : signal == SIGINT ? "SIGINT" : signal == SIGUSR1 ? "SIGUSR1" : "a signal";
      summary.checkpoint = options.restart;
      summary.simulated_time = solver.time();
      return summary;
    }
  }
  const long check_stride = 200;
  const long first = solver.steps_done();

  long last_frame_step = -1;
  auto write_current_frame = [&](bool stress_current = false) {
    if (history_file) history_file->sync();
    last_frame_step = solver.steps_done();
    const FrameData frame = read_frame(model, solver, split.get(), stress_current);
    if (root) write_frame(*exodus_file, fragments.get(), model, frame, solver.time(), cl);
    place_outputs();
  };

  const std::string ckpt_path = checkpoint_path(p);
  auto write_checkpoint = [&]() {
    if (history_file) history_file->sync();  // every row up to the checkpoint is on disk
    const auto began = std::chrono::steady_clock::now();
    io::CheckpointData data;
    if (split) record_breaks();  // the whole catalogue up to now, for the file's break log
    StateWriter out(cl, data);
    solver.save_state(out);
    // A split run: rank 0 writes the whole model's state, as one rank would.
    if (split) data = split->gather_state(data, split_catalogue);
    stamp_checkpoint(data, p);
    data.text["device"] = cl.description();
    data.text["case_path"] = config.path;
    data.text["title"] = config.title;
    data.text["case_text"] = config.text;
    data.numbers["time"] = solver.time();
    data.numbers["dt"] = p.dt;
    data.numbers["worst_energy_error"] = summary.worst_energy_error;
    data.integers["broken_ce4"] = !solver.cohesive() ? 0
                                  : split          ? static_cast<std::int64_t>(split_catalogue.size())
                                                   : static_cast<std::int64_t>(solver.cohesive()->count_broken());
    if (root) {
      // The files this checkpoint continues are in place, and it lists what they hold.
      place_outputs();
      data.text[kExodusDigests] = io::digests_text(exodus_file->frame_digests());
      data.text[kHistoryDigests] = io::digests_text(history_file->row_digests());
      if (fragments) data.text[kFragmentDigests] = io::digests_text(fragments->frame_digests());
      io::write_checkpoint_file(ckpt_path, data);
    }
    summary.checkpoint = ckpt_path;
    summary.checkpoint_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  };
  const double checkpoint_every = config.output.checkpoint_every;
  // The first multiple of checkpoint_every after time t, reckoned (never a loop of
  // additions, which makes no progress once the interval is below the resolution of t).
  auto checkpoint_after = [&](double t) {
    const double next = (std::floor(t / checkpoint_every + 1e-9) + 1) * checkpoint_every;
    return next > t ? next : std::nextafter(t, HUGE_VAL);
  };
  double next_checkpoint = checkpoint_every > 0 ? checkpoint_after(solver.time()) : 0;

  std::vector<double> last_row;
  size_t next_frame = 0;
  while (next_frame < frames.size() && frames[next_frame] <= first) ++next_frame;
  if (!resumed && !frames.empty() && frames[0] == 0) {
    write_current_frame();
    next_frame = 1;
  }
  solver.save_checkpoint();
  solver.release_output();

  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  int last_decile = 0;
  const double energy_limit = config.output.energy_limit;
  bool energy_warned = false;
  EnergyTotals last_energy;
  for (long s = first + 1; s <= p.steps; ++s) {
    const bool history_due = s % history_stride == 0 || s == p.steps;
    solver.step(history_due);
    if (split) split->exchange();
    const bool frame_due = next_frame < frames.size() && frames[next_frame] == s;
    const bool checkpoint_due = checkpoint_every > 0 && solver.time() >= next_checkpoint - 1e-6 * p.dt;
    int stop_number = options.stop ? static_cast<int>(*options.stop) : 0;
    bool out_of_time = options.max_wall > 0 &&
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > options.max_wall;
    if (split) {
      // Every rank must stop at the same step: a signal or --max-wall on any rank counts at
      // the next step where the ranks talk anyway (at most check_stride steps later).
      const bool talk = frame_due || history_due || checkpoint_due || s % check_stride == 0;
      stop_number = talk ? static_cast<int>(transport->max(stop_number)) : 0;
      out_of_time = talk && transport->max(out_of_time ? 1 : 0) != 0;
    }
    const bool stop_signal = stop_number != 0;
    const bool stopping = (stop_signal || out_of_time) && s < p.steps;
    if (frame_due || history_due || checkpoint_due || stopping || s % check_stride == 0) {
      // One rank: the conditions, and at a history row the energy account and the
      // positions and forces its columns read, are queued together and land with one wait
      // for the device (RowReads), instead of a wait per read.
      std::function<EnergyTotals()> energy_later;
      std::function<std::vector<real2>()> positions_later, forces_later;
      std::function<Conditions()> conditions_later;
      if (!split) {
        solver.row_reads().begin();
        conditions_later = solver.queue_conditions();
        if (history_due) {
          energy_later = solver.queue_energy();
          positions_later = solver.queue_positions();
          forces_later = solver.queue_forces();
        }
      }
      const Conditions cond = split ? split->conditions(solver) : conditions_later();
      if (!cond.ok()) {
        failure_agreed() = true;  // every rank of a split run found the same
        const std::string what = describe_failure(model, cond);
        std::string saved;
        if (solver.has_checkpoint()) {
          solver.restore_checkpoint();
          try {
            if (solver.steps_done() != last_frame_step) write_current_frame();
            saved = "; the last good state (step " + std::to_string(solver.steps_done()) + ", t = " +
                    format_number(solver.time()) + " s) is the last frame of " + p.exodus_path;
          } catch (const std::exception&) {
            saved = "";  // the stress of the last good state may itself be invalid
          }
        }
        if (status_line) log << "\n";
        throw NumericalError(what + saved);
      }
      bool stress_current = false;
      if (history_due || checkpoint_due || stopping) record_breaks();
      if (history_due) {
        const EnergyTotals energy = energy_later ? energy_later() : solver.energy();
        const double error = solver.balance().error(energy);
        HistoryRow row(solver, points, energy, error, solver.balance().ratio(energy));
        if (positions_later) row.prefetch(positions_later, forces_later);
        if (split) {
          // The whole model's values on rank 0, in global order (what the columns read).
          auto x = split->gather(ItemKind::Node, solver.positions());
          auto f = split->gather(ItemKind::Node, solver.forces());
          std::vector<int> broken, mode;
          if (ce4) broken = split->gather(ItemKind::Ce4, ce4->broken()), mode = split->gather(ItemKind::Ce4, ce4->mode());
          std::vector<int> labels;
          if (ce4 && root) labels = host_fragment_labels(model, broken);
          row.provide(std::move(x), std::move(f), std::move(broken), std::move(mode), std::move(labels));
          if (!points.empty()) row.provide_probes(split->probe_values(solver, p.probes));
        }
        if (root) {
          last_row = table_holder->values(row);
          history_file->append(solver.time(), last_row);
        }
        stress_current = row.stress_evaluated();
        summary.worst_energy_error = std::max(summary.worst_energy_error, std::fabs(error));
        summary.final_energy_error = error;
        const std::string grew = EnergyBalance::largest_change(last_energy, energy);
        last_energy = energy;
        if (std::fabs(error) > energy_limit) {
          failure_agreed() = true;  // the account is the same on every rank
          if (status_line) log << "\n";
          std::string saved;
          try {
            if (solver.steps_done() != last_frame_step) write_current_frame();
            saved = "; the state at this step is the last frame of " + p.exodus_path;
          } catch (const std::exception&) {
          }
          throw NumericalError("step " + std::to_string(solver.steps_done()) + ", t = " +
                               format_number(solver.energy_time()) + " s: energy_error " + format_number(error, 3) +
                               " exceeds output.energy_limit = " + format_number(energy_limit, 3) +
                               " (the energy balance does not close; " + grew +
                               " changed most since the last history row)" + saved);
        }
        if (std::fabs(error) > 0.01 && !energy_warned) {
          energy_warned = true;
          if (status_line) log << "\n";
          log << "warning: step " << solver.steps_done() << ", t = " << format_number(solver.energy_time())
              << " s: energy_error " << format_number(error, 3) << " is above 1% (" << grew
              << " changed most since the last history row)\n";
        }
      }
      if (frame_due) {
        write_current_frame(stress_current);
        ++next_frame;
      }
      // The copy a NaN rolls back to: at the checks every check_stride steps and at frames
      // and checkpoints, not at every history row (a row every few steps would read the
      // positions and velocities back that often; the copy stays a passed state at most
      // check_stride steps old).
      if (s % check_stride == 0 || frame_due || checkpoint_due) solver.save_checkpoint();
      solver.release_output();  // the output arrays of this step (stress) until the next output
      cl.collect_profile();
      if (checkpoint_due) {
        write_checkpoint();
        next_checkpoint = checkpoint_after(solver.time() + 1e-6 * p.dt);
      }
      if (stopping) {
        summary.interrupted = true;
        if (stop_signal) {
          const int signal = stop_number;
          summary.stop_reason = signal == SIGTERM ? "SIGTERM" : signal == SIGINT ? "SIGINT" : signal == SIGUSR1 ? "SIGUSR1" : "a signal";
        } else {
          summary.stop_reason = "--max-wall " + format_number(options.max_wall) + " s";
        }
        break;
      }
    }

    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (status_line && (std::chrono::duration<double>(now - last_report).count() > 0.5 || s == p.steps)) {
      last_report = now;
      const double rate = (s - first) / std::max(elapsed, 1e-9);
      log << "\rstep " << s << "/" << p.steps << "  t = " << format_number(solver.time()) << " s  "
          << std::fixed << std::setprecision(1) << 100.0 * s / p.steps << "%  " << std::setprecision(0)
          << rate << " steps/s  ETA " << std::setprecision(1) << (p.steps - s) / rate << " s   "
          << std::defaultfloat << std::flush;
    } else if (!status_line) {
      const int decile = static_cast<int>(10 * s / p.steps);
      if (decile > last_decile) {
        last_decile = decile;
        log << "  " << decile * 10 << "%  step " << s << "/" << p.steps << "  t = " << format_number(solver.time())
            << " s  " << std::fixed << std::setprecision(0) << (s - first) / std::max(elapsed, 1e-9) << " steps/s"
            << std::defaultfloat << "\n" << std::flush;
      }
    }
  }
  cl.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (status_line) log << "\n";

  write_checkpoint();  // every run ends with one, finished or stopped
  summary.steps = solver.steps_done() - first;
  summary.simulated_time = solver.time();
  summary.wall_seconds = wall;
  summary.ns_per_element_step =
      1e9 * wall / (double(std::max(1L, summary.steps)) * std::max<size_t>(1, model.num_triangles()));
  summary.frames = exodus_file ? exodus_file->frames_written() : 0;
  if (!last_row.empty()) {
    summary.final_kinetic_energy = last_row[table_holder->index("kinetic_energy")];
    summary.final_unbalanced_ratio = last_row[table_holder->index("unbalanced_ratio")];
  }
  if (exodus_file) exodus_file->close();
  if (history_file) history_file->close();
  if (fragments) fragments->close();
  if (ce4) record_breaks();
  if (events) {
    const io::EventRule rule = event_rule(model, config.output.events_distance, config.output.events_window);
    const auto all = with_triangles(split ? split_catalogue : ce4->catalogue());
    const auto grouped = group_events(all, rule);
    events->finish(all, grouped, rule);
    summary.breaks = all.size();
    summary.events = grouped.size();
  }
  return summary;
}

}  // namespace fdem
