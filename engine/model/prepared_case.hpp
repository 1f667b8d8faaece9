// A case read, meshed and checked, ready to run (engine/run/prepare_case.hpp makes it).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "engine/model/model.hpp"
#include "engine/model/probes.hpp"
#include "io/case_config.hpp"

namespace fdem {

struct PreparedCase {
  io::CaseConfig config;
  Model model;
  std::vector<std::string> notes;  // re-oriented triangles, dropped nodes, ...
  StableStep stable;               // stable Δt estimate
  double dt = 0;                   // the Δt the run uses
  long steps = 0;                  // number of steps
  std::string exodus_path, history_path;
  std::string fragments_path;  // OUT/NAME_fragments.nc, written when the model has CE4s
  std::string events_path;  // OUT/NAME_events.nc: break catalogue and events (models with CE4s only)
  std::vector<ProbeLocation> probes;  // [[probe]] points tied to their node and triangle
};

// OUT/NAME.ckpt: where a case's checkpoints go.
inline std::string checkpoint_path(const PreparedCase& p) {
  return (std::filesystem::path(p.config.output.dir) / (p.config.output.name + ".ckpt")).string();
}

}  // namespace fdem
