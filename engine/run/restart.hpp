// Continuing a run from a checkpoint of the whole model (any number of ranks).
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "engine/run/domain.hpp"

namespace fdem {

struct Restart {
  // The digests of the records each earlier file held at the checkpoint, by the
  // checkpoint's attribute (io/output_resume.hpp).
  std::map<std::string, std::vector<std::uint64_t>> digests;
  double worst_energy_error = 0;
};

// Reads the checkpoint at `path` into `domain` (every rank its share). InputError, on
// every rank, when it does not fit the case (another mesh, precision or setting other
// than time.end and output.*) or is at or past the case's last step.
Restart load_restart(Domain& domain, const PreparedCase& p, const std::string& path);

}  // namespace fdem
