// `fdem bench`: the seed paper's Table 2 benchmark (uniaxial compression specimen at
// several element sizes, Δt 0.5 ns, every triangle a contact candidate).
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/device/cl_context.hpp"

namespace fdem {

struct BenchOptions {
  std::string case_path = "cases/ucs/case.toml";
  std::vector<double> sizes{0.6, 0.5, 0.4, 0.3, 0.2, 0.15};  // h_ave [mm] of Table 2
  long warmup = 20, steps = 200;
  // Rows beyond Table 2: the smallest size's mesh split into four (mesh.refine) once,
  // twice, … up to this many times (4.3M and 17M TRI3 from the 1.08M mesh).
  int refine_rows = 0;
  std::string csv;  // also write the table here when not empty
  // Fracturing rows (`--fracturing`), after the intact ones: the cases where rock breaks,
  // stepped as `fdem run` steps them (their own Δt, activation, skin and loads, no output):
  //   "blasting"    cases/blasting/case.toml over its first `blast_window` seconds, where
  //                 most of its CE4s break; "blasting:K" the same mesh split K times
  //                 (mesh.refine = K: 4^K times the TRI3, Δt halved K times);
  //   "ucs-fast"    cases/ucs/fast.toml over its whole run, across its peak.
  std::vector<std::string> fracturing;
  double blast_window = 400e-6;
  std::string cases_dir = "cases";  // where the fracturing rows' cases are
  // Fluid rows (`--fluid`): cases/kgd/viscosity.toml ("kgd"; "kgd:K" its mesh split K times)
  // over its first `fluid_window` seconds, stepped with its [fluid] stage and again, the same
  // model and steps, without it: what the fluid costs a step (issue 32: at most 30% more).
  std::vector<std::string> fluid;
  double fluid_window = 1e-3;
  // `--set KEY=VALUE` case overrides, applied to every row after the bench's own keys
  // (e.g. material.0.fracture.model="extrinsic" for the extrinsic model's rows).
  std::vector<std::string> overrides;
};

// The names `--fracturing` accepts ("all": blasting, blasting:2, blasting:3, ucs-fast).
// Throws InputError for anything else.
std::vector<std::string> fracturing_rows(const std::string& list);

// The names `--fluid` accepts ("kgd", "kgd:K" with K = 0 to 3). Throws InputError for others.
std::vector<std::string> fluid_rows(const std::string& list);

// Runs the benchmark rows on `device` (a ClContext choice) and prints the table to `out`.
// Returns 0.
int run_bench(const BenchOptions& options, const std::string& device, std::ostream& out);

}  // namespace fdem
