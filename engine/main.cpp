// fdem: the command-line front end. Library code throws typed errors; this file alone
// turns them into messages and exit codes (0 done, 2 bad input, 3 numerical failure,
// 4 device error, 5 output error, 75 stopped cleanly with a checkpoint to resume from).
#include <cmath>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <csignal>
#include <filesystem>

#include <boost/compute/exception.hpp>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "engine/model/fluid_spring.hpp"
#include "engine/bench.hpp"
#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "base/errors.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "engine/stages/contact_detection.hpp"
#include "engine/stages/contact_forces.hpp"
#include <cstdlib>
#include "engine/parallel/partition.hpp"
#include "engine/run/split_run.hpp"
#include "engine/parallel/transport.hpp"
#include "io/checkpoint_file.hpp"
#include "io/gmsh_reader.hpp"

namespace {

const char* kUsage =
    "usage:\n"
    "  fdem run CASE.toml [--device auto|gpu|cpu|P:D] [--set KEY=VALUE]... [--quiet] [--profile]\n"
    "  mpirun -np N fdem run CASE.toml [--device gpu|cpu] [--partition metis|bisection]   (one model over N ranks)\n"
    "           [--restart [CHECKPOINT]] [--max-wall SECONDS] [--contact-travel METRES (split runs)]\n"
    "  fdem check CASE.toml [--device ...] [--set KEY=VALUE]... [--ranks N [--partition metis|bisection]\n"
    "             [--contact-travel METRES]] [--memory]\n"
    "  fdem check CHECKPOINT.ckpt\n"
    "  fdem devices\n"
    "  fdem bench [--device ...] [--sizes 0.6,0.5,...|none] [--steps N] [--refine-rows K]\n"
    "             [--fracturing blasting,blasting:2,ucs-fast|all] [--window S] [--fluid kgd,kgd:K]\n"
    "             [--fluid-window S] [--csv FILE]\n"
    "             [--case cases/ucs/case.toml]\n"
    "  fdem --version\n"
    "  fdem COMMAND --help   (that command's options)\n"
    "The device defaults to $FDEM_DEVICE, else auto (first GPU with fp64, else a CPU device).\n";

// Every option of every command: its spelling, the value it takes ("" for a switch) and
// what it does. Each command lists the options it accepts (kCommands); any other option
// is refused, naming the command, rather than ignored.
struct OptionSpec {
  const char* name;
  const char* value;
  const char* help;
};

const OptionSpec kOptions[] = {
    {"--device", "auto|gpu|cpu|P:D", "the OpenCL device (P:D as `fdem devices` lists them); default $FDEM_DEVICE, else auto"},
    {"--set", "KEY=VALUE", "override a case key, e.g. --set time.end=0.01 (repeatable)"},
    {"--quiet", "", "no progress lines (the header, warnings, errors and the summary stay); also -q"},
    {"--profile", "", "device time per kernel at the end"},
    {"--restart", "[CHECKPOINT]", "continue from a checkpoint (default OUT/NAME.ckpt)"},
    {"--max-wall", "SECONDS", "stop with a checkpoint once this wall time has passed (exit 75)"},
    {"--ranks", "N", "print how the model would be split over N ranks"},
    {"--partition", "metis|bisection", "how the model is split over ranks (default metis where built with it)"},
    {"--contact-travel", "METRES", "how far a node may move between contact ghost updates of a split run"},
    {"--memory", "", "the device memory plan, array by array"},
    {"--max-triangles", "N", "refuse a .geo mesh whose estimated triangle count is above N (default 5000000)"},
    {"--allow-geo-programs", "", "let a .geo file run programs (SystemCall, OnelabRun, ...): only for .geo files you trust"},
    {"--sizes", "H,H,...", "element sizes h_ave in mm (default 0.6,0.5,0.4,0.3,0.2,0.15; none: no intact rows)"},
    {"--steps", "N", "timed steps per row (default 200)"},
    {"--refine-rows", "K", "add rows of the smallest size refined 1..K times by mesh.refine (0-3)"},
    {"--fracturing", "ROWS", "add rows where rock breaks: blasting, blasting:K (mesh.refine K), ucs-fast, or all"},
    {"--window", "SECONDS", "simulated time the blasting rows are timed over (default 400e-6)"},
    {"--fluid", "ROWS", "add fluid rows: kgd, kgd:K (cases/kgd/viscosity.toml, mesh.refine K), with and without [fluid]"},
    {"--fluid-window", "SECONDS", "simulated time the fluid rows are timed over (default 1e-3)"},
    {"--cases", "DIR", "where --fracturing and --fluid find blasting/case.toml, ucs/fast.toml and kgd/viscosity.toml (default cases)"},
    {"--csv", "FILE", "also write the rows as CSV"},
    {"--case", "CASE.toml", "the case to mesh at each size (default cases/ucs/case.toml)"},
};

struct CommandSpec {
  const char* name;
  const char* synopsis;
  const char* about;
  std::vector<std::string> options;
};

const std::vector<CommandSpec>& commands() {
  static const std::vector<CommandSpec> list = {
      {"run",
       "fdem run CASE.toml [OPTION]...\n       mpirun -np N fdem run CASE.toml [OPTION]...   (one model split over N ranks)",
       "Meshes and runs a case; writes OUT/NAME.exo, OUT/NAME_history.nc and a checkpoint OUT/NAME.ckpt.\n"
       "SIGTERM, SIGINT or SIGUSR1 stop it at the next step with a checkpoint (exit 75).",
       {"--device", "--set", "--quiet", "--profile", "--restart", "--max-wall", "--partition", "--contact-travel",
        "--max-triangles", "--allow-geo-programs"}},
      {"check", "fdem check CASE.toml [OPTION]...\n       fdem check CHECKPOINT.ckpt",
       "Reads and meshes a case without running it: counts, stable dt, steps, device memory; or\n"
       "describes a checkpoint. Refuses what `fdem run` would refuse, with the same message.",
       {"--device", "--set", "--quiet", "--ranks", "--partition", "--contact-travel", "--memory", "--max-triangles",
        "--allow-geo-programs"}},
      {"devices", "fdem devices", "Lists the OpenCL devices, as --device P:D names them.", {}},
      {"bench", "fdem bench [OPTION]...",
       "The seed paper's Table 2: the UCS specimen at several element sizes, ms/step and device memory;\n"
       "with --fracturing, rows where rock breaks (the blasting case, refined, and the fast UCS test);\n"
       "with --fluid, the KGD case with and without its fluid stage.",
       {"--device", "--set", "--sizes", "--steps", "--refine-rows", "--fracturing", "--window", "--fluid",
        "--fluid-window", "--cases", "--csv",
        "--case", "--max-triangles", "--allow-geo-programs"}},
  };
  return list;
}

const CommandSpec* find_command(const std::string& name) {
  for (const auto& c : commands())
    if (name == c.name) return &c;
  return nullptr;
}

const OptionSpec* find_option(const std::string& name) {
  for (const auto& o : kOptions)
    if (name == o.name) return &o;
  return nullptr;
}

std::string command_help(const CommandSpec& c) {
  std::ostringstream out;
  out << "usage: " << c.synopsis << "\n" << c.about << "\n";
  if (c.options.empty()) {
    out << "It takes no options.\n";
    return out.str();
  }
  out << "options:\n";
  for (const auto& name : c.options) {
    const OptionSpec& o = *find_option(name);
    const std::string head = std::string(o.name) + (*o.value ? std::string(" ") + o.value : std::string());
    out << "  " << std::left << std::setw(34) << head << " " << o.help << "\n";
  }
  out << "  " << std::left << std::setw(34) << "--help" << " this text\n";
  return out.str();
}

struct Arguments {
  std::string command, case_path, device;
  std::vector<std::string> overrides;
  bool quiet = false;
  bool profile = false;
  bool restart = false;
  std::string restart_file;  // empty with --restart: OUT/NAME.ckpt
  double max_wall = 0;
  int ranks = 0;                  // fdem check --ranks N: print the partition over N ranks
  std::string partition;          // "metis" or "bisection"; empty: metis when built with it
  double contact_travel = 0;      // mpirun ... --contact-travel D: how far a node may move (split runs with contact)
  bool memory = false;            // fdem check --memory: the device memory plan, array by array
  long max_triangles = 0;         // --max-triangles N: the .geo meshing limit; 0: io::GeoMeshing's default
  bool allow_geo_programs = false;  // --allow-geo-programs: .geo files may run programs
  bool help = false;              // fdem COMMAND --help
  fdem::BenchOptions bench;
};

Arguments parse(int argc, char** argv) {
  Arguments a;
  if (argc < 2) throw fdem::InputError(std::string("no command given\n") + kUsage);
  a.command = argv[1];
  const CommandSpec* command = find_command(a.command);
  if (!command) throw fdem::InputError("unknown command '" + a.command + "'\n" + kUsage);
  for (int i = 2; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      a.help = true;
      return a;
    }
  for (int i = 2; i < argc; ++i) {
    std::string arg = argv[i];
    // --name=value is --name value.
    std::string inline_value;
    bool has_inline = false;
    if (arg.rfind("--", 0) == 0 && arg.find('=') != std::string::npos) {
      inline_value = arg.substr(arg.find('=') + 1);
      arg = arg.substr(0, arg.find('='));
      has_inline = true;
    }
    if (arg == "-q") arg = "--quiet";
    if (!arg.empty() && arg[0] == '-') {
      const OptionSpec* spec = find_option(arg);
      const std::string usage_hint = " (fdem " + a.command + " --help lists its options)";
      if (!spec) throw fdem::InputError("fdem " + a.command + ": unknown option '" + arg + "'" + usage_hint);
      if (std::find(command->options.begin(), command->options.end(), arg) == command->options.end()) {
        std::string owners;
        for (const auto& c : commands())
          if (std::find(c.options.begin(), c.options.end(), arg) != c.options.end())
            owners += std::string(owners.empty() ? "" : " and ") + "fdem " + c.name;
        throw fdem::InputError("fdem " + a.command + " does not take " + arg + " (it belongs to " + owners + ")" + usage_hint);
      }
      if (has_inline && !*spec->value) throw fdem::InputError(arg + " takes no value, not '" + inline_value + "'");
    }
    auto value = [&](const std::string& flag) {
      if (has_inline) return inline_value;
      if (i + 1 >= argc) throw fdem::InputError(flag + " needs a value");
      return std::string(argv[++i]);
    };
    if (arg == "--device") a.device = value(arg);
    else if (arg == "--set") a.overrides.push_back(value(arg));
    else if (arg == "--quiet") a.quiet = true;
    else if (arg == "--restart") {
      a.restart = true;
      // An optional file: the next word unless it is an option or the case file still to come.
      if (has_inline) a.restart_file = inline_value;
      else if (i + 1 < argc && argv[i + 1][0] != '-' && !(a.case_path.empty() && std::string(argv[i + 1]).size() > 5 &&
                                                          std::string(argv[i + 1]).substr(std::string(argv[i + 1]).size() - 5) == ".toml"))
        a.restart_file = argv[++i];
    } else if (arg == "--max-wall") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        a.max_wall = std::stod(v, &used);
        if (used != v.size() || !(a.max_wall > 0)) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw fdem::InputError("--max-wall needs a positive number of seconds, not '" + v + "'");
      }
    }
    else if (arg == "--profile") a.profile = true;
    else if (arg == "--memory") a.memory = true;
    else if (arg == "--allow-geo-programs") a.allow_geo_programs = true;
    else if (arg == "--max-triangles") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        const double n = std::stod(v, &used);  // 2e7 as well as 20000000
        if (used != v.size() || !(n >= 1) || n > 9.2e18 || n != std::floor(n)) throw std::invalid_argument(v);
        a.max_triangles = static_cast<long>(n);
      } catch (const std::exception&) {
        throw fdem::InputError("--max-triangles needs a whole number of triangles, 1 or more, not '" + v + "'");
      }
    }
    else if (arg == "--ranks") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        a.ranks = std::stoi(v, &used);
        if (used != v.size() || a.ranks < 1) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw fdem::InputError("--ranks needs a whole number of ranks, 1 or more, not '" + v + "'");
      }
    } else if (arg == "--contact-travel") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        a.contact_travel = std::stod(v, &used);
        if (used != v.size() || !(a.contact_travel > 0) || !std::isfinite(a.contact_travel)) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw fdem::InputError("--contact-travel needs a length in metres above 0, not '" + v + "'");
      }
    } else if (arg == "--partition") {
      a.partition = value(arg);
      if (a.partition != "metis" && a.partition != "bisection")
        throw fdem::InputError("--partition: unknown method '" + a.partition + "' (metis or bisection)");
    }
    else if (arg == "--sizes") {
      a.bench.sizes.clear();
      const std::string sizes = value(arg);
      if (sizes == "none") continue;  // fracturing rows only
      std::istringstream list(sizes);
      std::string item;
      while (std::getline(list, item, ','))
        try {
          a.bench.sizes.push_back(std::stod(item));
        } catch (const std::exception&) {
          throw fdem::InputError("--sizes: '" + item + "' is not a number (h_ave in mm, e.g. 0.6,0.3)");
        }
    } else if (arg == "--steps") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        a.bench.steps = std::stol(v, &used);
        if (used != v.size() || a.bench.steps < 1) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw fdem::InputError("--steps needs a whole number of steps, 1 or more, not '" + v + "'");
      }
    } else if (arg == "--refine-rows") {
      const std::string v = value(arg);
      if (v.empty() || v.size() > 1 || v[0] < '0' || v[0] > '3')
        throw fdem::InputError("--refine-rows needs 0, 1, 2 or 3 (levels of mesh.refine on the smallest size)");
      a.bench.refine_rows = v[0] - '0';
    } else if (arg == "--fracturing") {
      a.bench.fracturing = fdem::fracturing_rows(value(arg));
    } else if (arg == "--fluid") {
      a.bench.fluid = fdem::fluid_rows(value(arg));
    } else if (arg == "--fluid-window") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        a.bench.fluid_window = std::stod(v, &used);
        if (used != v.size() || !(a.bench.fluid_window > 0) || !(a.bench.fluid_window <= 1)) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw fdem::InputError("--fluid-window needs a time in seconds above 0 and at most 1, not '" + v + "'");
      }
    } else if (arg == "--cases") {
      a.bench.cases_dir = value(arg);
    } else if (arg == "--window") {
      const std::string v = value(arg);
      try {
        size_t used = 0;
        a.bench.blast_window = std::stod(v, &used);
        if (used != v.size() || !(a.bench.blast_window > 0) || !(a.bench.blast_window <= 1)) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw fdem::InputError("--window needs a time in seconds above 0 and at most 1, not '" + v + "'");
      }
    } else if (arg == "--csv") a.bench.csv = value(arg);
    else if (arg == "--case") a.bench.case_path = value(arg);
    else if (!arg.empty() && arg[0] == '-') throw fdem::InputError("unknown option '" + arg + "'\n" + kUsage);
    else if (a.command != "run" && a.command != "check")
      throw fdem::InputError("fdem " + a.command + " takes no file argument, not '" + arg + "' (fdem " + a.command +
                             " --help lists its options)");
    else if (a.case_path.empty()) a.case_path = arg;
    else throw fdem::InputError("unexpected argument '" + arg + "'\n" + kUsage);
  }
  return a;
}

// The case or checkpoint named on the command line: something other than a regular file
// (a directory, a FIFO, /dev/zero) is named as what it is, not read.
void check_input_file(const std::string& path, const char* what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (!fs::exists(st)) return;  // the reader says "not found", naming the file
  if (fs::is_directory(st)) throw fdem::InputError(path + ": is a directory, not a " + what);
  if (!fs::is_regular_file(st))
    throw fdem::InputError(path + ": is not a regular file (" +
                           (fs::is_fifo(st) ? std::string("a FIFO") : fs::is_character_file(st) ? std::string("a character device")
                                              : fs::is_block_file(st) ? std::string("a block device")
                                              : fs::is_socket(st)     ? std::string("a socket")
                                                                      : std::string("a special file")) +
                           "), not a " + what);
}

// `fdem check`'s line for [fluid.gas]: the gas's constants and its hole.
std::string gas_line(const fdem::FluidModel& f) {
  std::ostringstream o;
  o << "gas       gamma " << f.gamma << ", rho0 " << f.gas_density << " kg/m3, p0 " << f.gas_pressure << " Pa in hole '"
    << f.hole_name << "' (" << f.hole_volume << " m3, " << f.gas_density * f.hole_volume
    << " kg; K = gamma p0 in the stable steps)\n";
  return o.str();
}

std::string mib(size_t bytes) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << bytes / 1048576.0 << " MiB";
  return s.str();
}

int list_devices_command() {
  const auto devices = fdem::list_devices();
  if (devices.empty()) {
    std::cout << "no OpenCL devices (install pocl-opencl-icd for a CPU device, or a GPU driver)\n";
    return 4;
  }
  std::string platform;
  for (const auto& d : devices) {
    if (d.platform_name != platform) {
      platform = d.platform_name;
      std::cout << "platform " << d.platform_index << ": " << platform << "\n";
    }
    std::cout << "  " << d.platform_index << ":" << d.device_index << "  " << d.device_name << "  ["
              << (d.is_gpu ? "GPU" : "CPU") << "]  " << d.version << ", " << d.compute_units
              << " compute units, " << mib(d.global_memory) << ", fp64 " << (d.has_fp64 ? "yes" : "no") << "\n";
  }
  return 0;
}

void print_notes(const fdem::PreparedCase& p) {
  for (const auto& note : p.notes) std::cout << "note: " << note << "\n";
}

// `fdem check FILE.ckpt`: what a checkpoint holds.
int check_checkpoint(const std::string& path) {
  const auto data = fdem::io::read_checkpoint_file(path);
  auto text = [&](const char* k) { return data.text.count(k) ? data.text.at(k) : std::string("?"); };
  auto integer = [&](const char* k) { return data.integers.count(k) ? data.integers.at(k) : -1L; };
  auto number = [&](const char* k) { return data.numbers.count(k) ? data.numbers.at(k) : 0.0; };
  std::cout << "checkpoint " << path << " (" << mib(std::filesystem::file_size(path)) << ", format "
            << text("format_version") << ")\n"
            << "case       " << text("case_path") << (text("title").empty() ? "" : "  (" + text("title") + ")") << "\n"
            << "step       " << integer("step") << "\n"
            << "time       " << number("time") << " s (dt " << number("dt") << " s)\n"
            << "device     " << text("device") << "\n"
            << "precision  " << text("precision") << "\n"
            << "mesh       " << text("mesh_hash") << "\n"
            << "broken CE4 " << integer("broken_ce4") << "\n"
            // The records the output files held (one 16-digit digest and a space each):
            // what --restart checks the earlier files against.
            << "output     " << (text("exodus_frame_digests").size() + 1) / 17 << " frames, "
            << (text("history_row_digests").size() + 1) / 17 << " history rows\n"
            << "worst energy_error so far " << number("worst_energy_error") << "\n";
  return 0;
}

// `fdem check --ranks N`: each part's share of the model and what it would hold besides
// (engine/parallel/partition.hpp gives the ownership and ghost rules).
void print_partition(const Arguments& a, const fdem::Model& m) {
  using fdem::PartitionMethod;
  const PartitionMethod method = a.partition == "bisection" || (a.partition.empty() && !fdem::partition_has_metis())
                                     ? PartitionMethod::Bisection
                                     : PartitionMethod::Metis;
  const auto partition = fdem::partition_model(m, a.ranks, method);
  // The contact ghosts a split run holds (engine/run/split_run.hpp).
  const double reach = m.contact.enabled ? fdem::contact_ghost_reach(m, a.contact_travel > 0 ? a.contact_travel
                                                                                             : fdem::default_contact_travel(m))
                                         : 0.0;
  const auto stats = fdem::partition_stats(m, partition, reach);
  std::cout << "partition " << a.ranks << " ranks by " << fdem::partition_method_name(method)
            << " (work weights: TRI3 4, CE4 5 a side, contact candidate 100)\n"
            << "  rank       TRI3        CE4      nodes  ghost TRI3  ghost CE4 ghost nodes"
            << (m.contact.enabled ? " contact ghosts" : "") << "        work   held: TRI3        CE4      nodes\n";
  for (size_t r = 0; r < stats.size(); ++r) {
    const auto& s = stats[r];
    std::cout << std::setw(6) << r << std::setw(11) << s.tri3 << std::setw(11) << s.ce4 << std::setw(11) << s.nodes
              << std::setw(12) << s.ghost_tri3 << std::setw(11) << s.ghost_ce4 << std::setw(12) << s.ghost_nodes;
    if (m.contact.enabled) std::cout << std::setw(15) << s.contact_ghost_tri3;
    std::cout << std::setw(12) << s.work << std::setw(13) << s.held_tri3 << std::setw(11) << s.held_ce4 << std::setw(11)
              << s.held_nodes << "\n";
  }
  std::cout << "  imbalance " << std::fixed << std::setprecision(3) << fdem::partition_imbalance(stats)
            << " (largest part's work over the mean)" << std::defaultfloat << "\n";
}

// fdem check --memory: Solver::plan array by array (bytes as the device holds them, and
// per TRI3), largest first, then the growth of the contact lists to expected_couples.
void print_memory_plan(const fdem::Model& m, size_t group_size) {
  const fdem::MemoryPlan plan = fdem::Solver::plan(m, group_size);
  auto arrays = plan.arrays();
  std::stable_sort(arrays.begin(), arrays.end(), [](const auto& x, const auto& y) { return x.bytes > y.bytes; });
  const double tri3 = static_cast<double>(std::max<size_t>(1, m.num_triangles()));
  std::cout << "memory plan (" << arrays.size() << " arrays; B/TRI3 of " << m.num_triangles() << " TRI3):\n";
  for (const auto& x : arrays) {
    const size_t held = fdem::ClContext::allocation_size(x.bytes);
    const char* kind = x.lifetime == fdem::MemoryPlan::Lifetime::Resident ? ""
                       : x.lifetime == fdem::MemoryPlan::Lifetime::SetUp  ? "  (set-up)"
                       : x.lifetime == fdem::MemoryPlan::Lifetime::Output ? "  (output)"
                       : x.lifetime == fdem::MemoryPlan::Lifetime::Detection ? "  (detection)"
                       : x.lifetime == fdem::MemoryPlan::Lifetime::EnergyRow ? "  (energy row)"
                                                                          : "  (scratch)";
    std::cout << "  " << std::left << std::setw(44) << x.name << std::right << std::setw(12) << mib(held)
              << std::setw(9) << std::fixed << std::setprecision(1) << held / tri3 << std::defaultfloat << kind << "\n";
  }
  const size_t needed = fdem::Solver::bytes_needed(m, group_size);
  std::cout << "  resident " << mib(plan.resident()) << ", largest transient " << mib(plan.largest_transient())
            << ", contact lists grown to the expected couples + " << mib(needed - plan.total()) << ": "
            << mib(needed) << ", " << std::fixed << std::setprecision(1) << needed / tri3 << std::defaultfloat
            << " B/TRI3\n";
}

int check_command(const Arguments& a) {
  // A checkpoint, or the one before it that every checkpoint keeps.
  const auto ends_with = [&](const std::string& tail) {
    return a.case_path.size() > tail.size() && a.case_path.compare(a.case_path.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends_with(".ckpt") || ends_with(".ckpt.prev")) return check_checkpoint(a.case_path);
  const auto p = fdem::prepare_case(a.case_path, a.overrides);
  print_notes(p);
  const auto& m = p.model;
  std::cout << "case      " << p.config.path << (p.config.title.empty() ? "" : "  (" + p.config.title + ")") << "\n"
            << "mesh      " << m.mesh_path << "\n"
            << "nodes     " << m.num_nodes() << "\n"
            << "TRI3      " << m.num_triangles() << "\n";
  for (size_t k = 0; k < m.materials.size(); ++k)
    std::cout << "  material '" << m.materials[k].name << "': " << m.block_start[k + 1] - m.block_start[k]
              << " TRI3, viscosity " << m.materials[k].viscosity << " Pa s\n";
  std::cout << "regions   ";
  for (const auto& r : m.regions) std::cout << r.name << " (" << r.nodes.size() << " nodes" << (r.prescribed ? ", prescribed" : "") << ")  ";
  std::cout << "\nloaded edges " << m.loaded_edges.size() << "\n";
  if (!m.ce4.empty()) std::cout << "CE4       " << m.ce4.size() << " cohesive elements\n";
  if (const std::string e = fdem::extrinsic_summary(m); !e.empty()) std::cout << "extrinsic " << e << "\n";
  if (m.in_situ.enabled) std::cout << "in-situ   " << fdem::in_situ_summary(m) << "\n";
  for (const auto& line : fdem::heterogeneity_summary(m, p.config)) std::cout << "weibull   " << line << "\n";
  for (const auto& line : fdem::joint_summary(m, p.config)) std::cout << "joint     " << line << "\n";
  if (const std::string line = fdem::grains_summary(m, p.config); !line.empty()) std::cout << "grains    " << line << "\n";
  for (const auto& line : fdem::excavation_summary(m)) std::cout << "excavation " << line << "\n";
  for (const auto& warning : fdem::model_warnings(m, p.config, p.dt)) std::cout << "warning: " << warning << "\n";
  for (const auto& probe : p.probes)
    std::cout << "probe     " << probe.name << " at (" << probe.point[0] << ", " << probe.point[1] << "): node "
              << m.node_tags[probe.node] << " at (" << m.x[probe.node] << ", " << m.y[probe.node] << "), "
              << probe.node_distance << " m away; TRI3 " << m.triangle_tags[probe.triangle] << " (element "
              << probe.triangle + 1 << " of the Exodus file)\n";
  std::cout << "stable dt " << p.stable.dt << " s (triangle " << m.triangle_tags[p.stable.triangle] << ")\n"
            << "case dt   " << p.dt << " s" << (m.mass_scaling ? " (mass scaling: any dt is stable)" : "")
            << (p.config.time.dt_auto ? " (auto)" : "") << "\n"
            << "steps     " << p.steps << "\n";
  if (m.fluid.enabled)  // the flow's own stable step (cubic law and K_f at fluid.max_aperture)
    std::cout << "fluid     " << m.fluid.vertices << " network vertices, " << m.fluid.crack_ce4.size()
              << " CE4s on the crack, source '" << m.fluid.source_name << "' (" << m.fluid.source_vertices.size()
              << " vertices, " << (m.fluid.gas ? "the gas's hole" : m.fluid.pressure_source ? "pressure" : "rate") << ")\n"
              << (m.fluid.gas ? gas_line(m.fluid) : std::string())
              << "fluid dt  " << m.fluid.stable_dt << " s stable (CE4 " << m.fluid.shortest_ce4 << ", w_max "
              << m.fluid.max_aperture << " m), " << fdem::FluidFlow::substeps(m.fluid, p.dt)
              << " sub-steps per step\n"
              << "fluid k   the fluid's spring (9/16) K_f h t / w_r is stable below " << fdem::fluid_spring(m).dt
              << " s (CE4 " << fdem::fluid_spring(m).ce4 << ")" << (m.mass_scaling ? " (unscaled masses)" : "")
              << (p.dt < fdem::fluid_spring(m).dt ? "" : ": the case dt is above it") << "\n";
  // Where the files go: what `fdem run` would write, in a folder it can write (checked
  // below, after the device, in the order `fdem run` meets them).
  std::cout << "output    " << std::filesystem::absolute(p.config.output.dir).lexically_normal().string() << "/ ("
            << std::filesystem::path(p.exodus_path).filename().string() << ", "
            << std::filesystem::path(p.history_path).filename().string()
            << (m.ce4.empty() ? std::string()
                              : ", " + std::filesystem::path(p.fragments_path).filename().string() + ", " +
                                    std::filesystem::path(p.events_path).filename().string())
            << ", " << std::filesystem::path(fdem::checkpoint_path(p)).filename().string() << ")\n";
  if (a.ranks > 0) print_partition(a, m);
  // The device as `fdem run` opens it: a selection it cannot use is refused the same way.
  std::unique_ptr<fdem::ClContext> device;
  std::exception_ptr no_device;
  try {
    device = std::make_unique<fdem::ClContext>(a.device);
  } catch (const fdem::DeviceError&) {
    no_device = std::current_exception();
  }
  // What the Solver allocates (Solver::plan); the work-group size changes only the
  // per-group slots (without a device: 64, PoCL's).
  const size_t bytes = fdem::Solver::bytes_needed(m, device ? device->group_size() : 64);
  std::cout << "device memory needed " << mib(bytes);
  if (m.contact.enabled) std::cout << " (contact lists for " << fdem::Solver::expected_couples(m) << " couples)";
  std::cout << "\n";
  if (a.memory) print_memory_plan(m, device ? device->group_size() : 64);
  if (!device) std::rethrow_exception(no_device);
  fdem::check_output(p);
  {
    fdem::ClContext& cl = *device;
    std::cout << "device    " << cl.description() << ", " << mib(cl.info().global_memory)
              << (bytes > cl.info().global_memory ? "  -- TOO SMALL" : "  -- fits") << "\n";
    if (bytes > cl.info().global_memory) return 4;
    if (m.contact.enabled) {
      fdem::DeviceArrays arrays(cl, m);
      auto built = fdem::Solver::build_detection(true, cl, arrays, m);  // as the Solver's
      fdem::ContactDetection& detection = *built;
      const size_t couples = detection.run();
      const auto grid = detection.grid();
      std::cout << "contact   grid " << grid.nx << " x " << grid.ny << " cells of " << grid.cell_size
                << " m, " << couples << " initial candidate couples (boxes overlapping"
                << (m.contact.skin > 0 ? " with skin" : "") << ", not apart by more than the skin, no shared node)\n";
      std::cout << "          detection "
                << (m.contact.rebuild_skin ? "when a node may have moved half the skin, skin " : "every step, skin ")
                << m.contact.skin << " m"
                << (m.contact.skin_auto && m.node_owned.empty()
                        ? " at first (0.2 x the mean edge), then picked at each detection from the nodes' speeds (\"auto\")"
                        : m.contact.skin_auto ? " (0.2 x the mean edge; a split run keeps it)" : "")
                << "\n";
      // The figure above holds the contact lists at Solver::expected_couples; a first
      // list larger than that grows them further.
      const size_t group = cl.group_size(), expected = fdem::Solver::expected_couples(m);
      const size_t planned = std::max(expected, fdem::ContactForces::first_capacity(m.num_triangles()));
      if (couples > planned) {
        const size_t more = fdem::ContactForces::couple_arrays(fdem::ContactForces::grown(couples), group, !m.ce4_triangles.empty()).resident() -
                            fdem::ContactForces::couple_arrays(fdem::ContactForces::grown(planned), group, !m.ce4_triangles.empty()).resident();
        std::cout << "          more couples than the " << planned << " planned for: + " << mib(more)
                  << " once the run has started\n";
      }
    }
  }
  return 0;
}

// Started by mpirun (or another launcher) as one of several ranks: only `fdem run` of a
// build with MPI splits the model over them; anything else would have every rank do the
// whole work and write the same files, so refuse before doing anything. The launchers say
// so in the environment (Open MPI's mpirun; MPICH's Hydra and srun with PMI).
void refuse_parallel_launch(const std::string& command, bool split_run) {
  std::string name;
  const int ranks = fdem::launcher_ranks(&name);
  if (ranks <= 1 || (split_run && command == "run")) return;
  const std::string value = std::to_string(ranks);
  if (command == "run") {
#ifdef FDEM_HAVE_MPI
    throw fdem::InputError("started as one of " + value + " parallel ranks (" + name + "=" + value +
                           "), but not by an MPI launcher this fdem can join: start it with `mpirun -np N fdem run "
                           "CASE`, or run it as one process");
#else
    throw fdem::InputError("started as one of " + value + " parallel ranks (" + name + "=" + value +
                           "), but this fdem was built without MPI (Debian: libopenmpi-dev) and runs a model on one "
                           "device only: run it as one process. `fdem check CASE --ranks N` shows how the model would be split.");
#endif
  }
  throw fdem::InputError("started as one of " + value + " parallel ranks (" + name + "=" + value + "), but only `fdem " +
                         "run` splits a model over ranks: run `fdem " + command + "` as one process.");
}

// The MPI session of a split run (null otherwise), and its transport. Until the split run
// starts (split_run_command), every rank does the same (reads the same arguments), so an
// error there is every rank's.
fdem::MpiSession* g_mpi = nullptr;
std::unique_ptr<fdem::Transport> g_transport;
bool g_split_started = false;

// The device of this rank: with `gpu` (or `auto` when there is a GPU) the GPU of its
// rank on its node (round robin over the node's fp64 GPUs); otherwise as asked.
std::string rank_device(const std::string& asked, int local_rank) {
  std::string choice = asked;
  if (choice.empty()) {
    const char* env = std::getenv("FDEM_DEVICE");
    choice = env && *env ? env : "auto";
  }
  if (choice != "gpu" && choice != "auto") return choice;
  std::vector<fdem::DeviceInfo> gpus;
  for (const auto& d : fdem::list_devices())
    if (d.is_gpu && (d.has_fp64 || !fdem::kDoublePrecision)) gpus.push_back(d);
  if (gpus.empty()) return choice;
  const auto& d = gpus[static_cast<size_t>(local_rank) % gpus.size()];
  return std::to_string(d.platform_index) + ":" + std::to_string(d.device_index);
}

volatile std::sig_atomic_t g_stop = 0;
int g_stop_signal = 0;  // a signal that stopped fdem before run_case (main re-raises it)
extern "C" void request_stop(int signal) { g_stop = signal; }

// The command line that continues a stopped run from `checkpoint`.
std::string resume_command(const Arguments& a, const std::string& checkpoint) {
  std::string cmd = "fdem run " + a.case_path;
  if (!a.device.empty()) cmd += " --device " + a.device;
  for (const auto& o : a.overrides) cmd += " --set '" + o + "'";
  return cmd + " --restart " + checkpoint;
}

fdem::PartitionMethod partition_method(const Arguments& a) {
  return a.partition == "bisection" || (a.partition.empty() && !fdem::partition_has_metis())
             ? fdem::PartitionMethod::Bisection
             : fdem::PartitionMethod::Metis;
}

// --quiet: the run's log less its progress lines ("  40%  step 400/1000 ...", which
// engine/run/run.cpp writes when stderr is not a terminal); warnings pass through, in order
// with the rest of stdout.
class ProgressFilter : public std::streambuf {
 public:
  explicit ProgressFilter(std::ostream& out) : out_(out) {}
  ~ProgressFilter() override { flush_line(); }
  ProgressFilter(const ProgressFilter&) = delete;
  ProgressFilter& operator=(const ProgressFilter&) = delete;

 protected:
  int overflow(int c) override {
    if (c == traits_type::eof()) return traits_type::not_eof(c);
    line_ += static_cast<char>(c);
    if (c == '\n') flush_line();
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    for (std::streamsize k = 0; k < n; ++k) overflow(static_cast<unsigned char>(s[k]));
    return n;
  }

 private:
  static bool is_progress(const std::string& line) {
    size_t i = 0;
    while (i < line.size() && line[i] == ' ') ++i;
    const size_t digits = i;
    while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) ++i;
    return digits == 2 && i > digits && line.compare(i, 7, "%  step") == 0;
  }
  void flush_line() {
    if (!line_.empty() && !is_progress(line_)) out_ << line_ << std::flush;
    line_.clear();
  }
  std::ostream& out_;
  std::string line_;
};

// `mpirun -np N fdem run CASE`: every rank reads the case and runs its share
// (engine/run/split_run.*); rank 0 prints and writes the files.
int split_run_command(const Arguments& a) {
  fdem::Transport& t = *g_transport;
  g_split_started = true;
  const bool root = t.rank() == 0;
  std::unique_ptr<fdem::PreparedCase> p;
  std::unique_ptr<fdem::ClContext> cl;
  std::exception_ptr failure;
  try {
    p = std::make_unique<fdem::PreparedCase>(fdem::prepare_case(a.case_path, a.overrides));
    cl = std::make_unique<fdem::ClContext>(rank_device(a.device, g_mpi->local_rank()), a.profile);
  } catch (...) {
    failure = std::current_exception();
  }
  fdem::agree(t, failure);
  const std::string mine = cl->description();
  const std::vector<fdem::Bytes> devices = t.gather(fdem::Bytes(mine.begin(), mine.end()));
  std::ostringstream quiet;
  std::ostream& out = root ? std::cout : quiet;
  if (root) {
    print_notes(*p);
    out << "fdem " << FDEM_VERSION << ": " << p->config.path << " over " << t.size() << " ranks ("
        << fdem::partition_method_name(partition_method(a)) << " partition)\n";
    for (size_t r = 0; r < devices.size(); ++r)
      out << "  rank " << r << " on " << std::string(devices[r].begin(), devices[r].end()) << "\n";
    out << p->model.num_nodes() << " nodes, " << p->model.num_triangles() << " TRI3, dt " << p->dt << " s, " << p->steps
        << " steps\n" << std::flush;
  }
  fdem::RunOptions options;
  if (a.restart) options.restart = a.restart_file.empty() ? fdem::checkpoint_path(*p) : a.restart_file;
  options.max_wall = a.max_wall;
  options.info = &out;
  options.transport = &t;
  options.partition = partition_method(a);
  options.contact_travel = a.contact_travel;
  options.stop = &g_stop;  // mpirun passes SIGTERM and SIGINT on to the ranks
  for (int signal : {SIGTERM, SIGINT, SIGUSR1}) std::signal(signal, request_stop);
  ProgressFilter quiet_filter(out);
  std::ostream quiet_log(&quiet_filter);
  const auto s = fdem::run_case(*p, *cl, a.quiet ? quiet_log : out, false, options);
  if (s.interrupted) {
    out << "stopped by " << s.stop_reason << " at step " << s.first_step + s.steps << ", t = " << s.simulated_time
        << " s (" << s.steps << " steps run); checkpoint " << s.checkpoint << "\n"
        << "resume with: mpirun -np N " << resume_command(a, s.checkpoint) << " (any N)\n";
    return 75;
  }
  out << "done: " << s.steps << " steps over " << t.size() << " ranks, t = " << s.simulated_time << " s, wall "
      << std::fixed << std::setprecision(2) << s.wall_seconds << " s, " << std::setprecision(1)
      << s.steps / std::max(s.wall_seconds, 1e-9) << " steps/s\n"
      << std::defaultfloat << "final kinetic energy " << s.final_kinetic_energy << " J, unbalanced ratio "
      << s.final_unbalanced_ratio << ", energy_error " << std::setprecision(3) << s.final_energy_error << " (worst "
      << s.worst_energy_error << ")\n"
      << "wrote " << p->exodus_path << " (" << s.frames << " frames), " << p->history_path
      << (p->model.ce4.empty() ? std::string() : ", " + p->fragments_path + ", " + p->events_path) << " and "
      << s.checkpoint << " (the whole model's: it continues at any number of ranks)\n" << std::defaultfloat;
  if (a.profile) {
    // Every rank's profile, printed by rank 0 in rank order.
    cl->collect_profile();
    std::ostringstream mine;
    mine << "profile of rank " << t.rank() << " (device time per kernel; host-timed sections marked so):\n";
    for (const auto& [name, time] : cl->profile())
      mine << "  " << std::left << std::setw(60) << name << std::right << std::setw(10) << time.launches << " calls "
           << std::fixed << std::setprecision(3) << std::setw(10) << 1e3 * time.seconds << " ms " << std::setw(10)
           << 1e6 * time.seconds / std::max(1L, s.steps) << " us/step\n" << std::defaultfloat;
    const std::string text = mine.str();
    for (const auto& b : t.gather(fdem::Bytes(text.begin(), text.end()))) out << std::string(b.begin(), b.end());
  }
  return 0;
}

// How often the contact list was rebuilt and extended, and what each cost (host wall:
// each includes its one wait for a count), from the profile's host-timed sections.
void print_contact_list_profile(fdem::ClContext& cl, long steps, std::ostream& out) {
  const auto& profile = cl.profile();
  auto line = [&](const char* section, const char* what) {
    for (const auto& [name, t] : profile)
      if (name.rfind(section, 0) == 0 && t.launches > 0)
        out << "  " << what << ": " << t.launches << " (" << std::fixed << std::setprecision(1)
            << 1e3 * t.launches / std::max(1L, steps) << " per 1,000 steps), " << std::setprecision(3)
            << 1e3 * t.seconds / t.launches << " ms each\n" << std::defaultfloat;
  };
  line("contact detection (host wall", "contact detections");
}

int run_command(const Arguments& a) {
  if (g_transport) return split_run_command(a);
  const auto p = fdem::prepare_case(a.case_path, a.overrides);
  print_notes(p);
  fdem::ClContext cl(a.device, a.profile);
  std::cout << "fdem " << FDEM_VERSION << ": " << p.config.path << " on " << cl.description() << "\n"
            << p.model.num_nodes() << " nodes, " << p.model.num_triangles() << " TRI3, dt " << p.dt << " s, "
            << p.steps << " steps\n"
            << "output in " << std::filesystem::absolute(p.config.output.dir).lexically_normal().string() << "/\n"
            << std::flush;
  const bool status_line = !a.quiet && isatty(STDERR_FILENO);
  fdem::RunOptions options;
  if (a.restart) options.restart = a.restart_file.empty() ? fdem::checkpoint_path(p) : a.restart_file;
  options.max_wall = a.max_wall;
  options.stop = &g_stop;
  options.info = &std::cout;
  // SIGTERM (batch systems, kill), SIGINT (Ctrl-C), SIGUSR1 (a scheduler's warning):
  // finish the step, write a checkpoint, close the files, exit 75.
  for (int signal : {SIGTERM, SIGINT, SIGUSR1}) std::signal(signal, request_stop);
  ProgressFilter quiet_filter(std::cout);
  std::ostream quiet_log(&quiet_filter);
  const auto s = fdem::run_case(p, cl, status_line ? std::cerr : a.quiet ? quiet_log : std::cout, status_line, options);
  if (s.interrupted) {
    std::cout << "stopped by " << s.stop_reason << " at step " << s.first_step + s.steps << ", t = " << s.simulated_time
              << " s (" << s.steps << " steps run); checkpoint " << s.checkpoint << "\n"
              << "resume with: " << resume_command(a, s.checkpoint) << "\n";
    return 75;
  }
  std::cout << "done: " << s.steps << " steps, t = " << s.simulated_time << " s, wall " << std::fixed
            << std::setprecision(2) << s.wall_seconds << " s, " << std::setprecision(1)
            << s.steps / std::max(s.wall_seconds, 1e-9) << " steps/s, " << std::setprecision(2)
            << s.ns_per_element_step << " ns per element-step\n"
            << std::defaultfloat << "final kinetic energy " << s.final_kinetic_energy << " J, unbalanced ratio "
            << s.final_unbalanced_ratio << ", energy_error " << std::setprecision(3) << s.final_energy_error
            << " (worst " << s.worst_energy_error << ")\n"
            << "wrote " << p.exodus_path << " (" << s.frames << " frames), " << p.history_path
            << (p.model.ce4.empty() ? std::string() : ", " + p.fragments_path) << " and "
            << s.checkpoint << " (" << mib(std::filesystem::file_size(s.checkpoint)) << ", written in " << std::fixed
            << std::setprecision(2) << s.checkpoint_seconds << " s)\n" << std::defaultfloat;
  if (!p.model.ce4.empty())
    std::cout << "break catalogue: " << s.breaks << (s.breaks == 1 ? " CE4 broken, " : " CE4s broken, ") << s.events
              << (s.events == 1 ? " event" : " events") << ", in " << p.events_path << "\n";
  if (a.profile) {
    cl.collect_profile();
    std::cout << "profile (device time per kernel; output and history steps included):\n";
    for (const auto& [name, t] : cl.profile())
      std::cout << "  " << std::left << std::setw(60) << name << std::right << std::setw(10) << t.launches
                << " calls " << std::fixed << std::setprecision(3) << std::setw(10) << 1e3 * t.seconds << " ms "
                << std::setw(10) << 1e6 * t.seconds / s.steps << " us/step\n" << std::defaultfloat;
    print_contact_list_profile(cl, s.steps - s.first_step, std::cout);
    if (s.lean_classifications >= 0)
      std::cout << "  lean contact classifications (only the couples no bond carries): " << s.lean_classifications
                << " of " << s.steps << " steps\n";
  }
  return 0;
}

// An error in a split run: when every rank raised it together (failure_agreed), rank 0
// prints it and every rank returns the code; otherwise this rank alone failed while the
// others may wait for it, so it prints and ends them all (MPI_Abort with the code).
int fail(int code, const std::string& message) {
  if (!g_transport) {
    std::cerr << message << "\n";
    return code;
  }
  if (fdem::failure_agreed() || !g_split_started) {
    if (g_transport->rank() == 0) std::cerr << message << "\n";
    return code;
  }
  g_transport->abort(code, "rank " + std::to_string(g_transport->rank()) + ": " + message + "\n");
  return code;  // not reached: abort ends the process
}

int guarded_main(int argc, char** argv);

}  // namespace

int main(int argc, char** argv) {
  fdem::MpiSession mpi(&argc, &argv);
  int code = 0;
#ifdef FDEM_HAVE_MPI
  if (mpi.active() && mpi.size() > 1) {
    g_mpi = &mpi;
    g_transport = std::make_unique<fdem::MpiTransport>();
  }
#endif
  code = guarded_main(argc, argv);
  g_transport.reset();
  // Stopped by a signal before the run could write a checkpoint (while gmsh meshed): end
  // as that signal ends a process, so that a shell or batch system sees the signal.
  if (g_stop_signal && !mpi.active()) {
    std::cout.flush();
    std::signal(g_stop_signal, SIG_DFL);
    std::raise(g_stop_signal);
  }
  return code;
}

namespace {

int guarded_main(int argc, char** argv) {
  try {
    if (argc >= 2 && (std::string(argv[1]) == "--version" || std::string(argv[1]) == "version")) {
      std::cout << "fdem " << FDEM_VERSION << " (" << (fdem::kDoublePrecision ? "double" : "float") << " precision)\n";
      return 0;
    }
    if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" || std::string(argv[1]) == "help")) {
      if (argc >= 3 && std::string(argv[1]) == "help") {
        const CommandSpec* c = find_command(argv[2]);
        if (!c) throw fdem::InputError(std::string("unknown command '") + argv[2] + "'\n" + kUsage);
        std::cout << command_help(*c);
        return 0;
      }
      std::cout << kUsage;
      return 0;
    }
    const Arguments a = parse(argc, argv);
    if (a.help) {
      std::cout << command_help(*find_command(a.command));
      return 0;
    }
    // How .geo files are meshed (io/gmsh_reader.hpp): the limit, programs, progress.
    auto& meshing = fdem::io::geo_meshing();
    if (a.max_triangles > 0) meshing.max_triangles = a.max_triangles;
    meshing.allow_programs = a.allow_geo_programs;
    if (a.quiet) meshing.progress = nullptr;
    if (!a.case_path.empty()) check_input_file(a.case_path, a.case_path.size() > 5 && a.case_path.substr(a.case_path.size() - 5) == ".ckpt" ? "checkpoint" : "case file");
    if (!a.restart_file.empty()) check_input_file(a.restart_file, "checkpoint");
    if (a.command != "run" && a.command != "check") refuse_parallel_launch(a.command, false);
    if (a.command == "devices") return list_devices_command();
    if (a.command == "bench") {
      fdem::BenchOptions bench = a.bench;
      bench.overrides = a.overrides;
      return fdem::run_bench(bench, a.device, std::cout);
    }
    if (a.command == "run" || a.command == "check") {
      if (a.ranks > 0 && a.command != "check") throw fdem::InputError("--ranks belongs to fdem check");
      refuse_parallel_launch(a.command, g_transport != nullptr);
      if (a.case_path.empty()) throw fdem::InputError("fdem " + a.command + " needs a case file\n" + kUsage);
      return a.command == "run" ? run_command(a) : check_command(a);
    }
    throw fdem::InputError("unknown command '" + a.command + "'\n" + kUsage);
  } catch (const fdem::io::MeshingStopped& e) {
    g_stop_signal = e.signal;
    return fail(128 + e.signal, std::string("stopped: ") + e.what());
  } catch (const fdem::InputError& e) {
    return fail(2, std::string("error: ") + e.what());
  } catch (const fdem::NumericalError& e) {
    return fail(3, std::string("numerical failure: ") + e.what());
  } catch (const fdem::DeviceError& e) {
    return fail(4, std::string("device error: ") + e.what());
  } catch (const boost::compute::opencl_error& e) {
    return fail(4, std::string("device error: ") + e.what());
  } catch (const fdem::OutputError& e) {
    return fail(5, std::string("output error: ") + e.what());
  } catch (const std::bad_alloc&) {
    return fail(4, "error: out of host memory");
  }
}

}  // namespace
