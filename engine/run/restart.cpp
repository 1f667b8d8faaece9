#include "engine/run/restart.hpp"

#include <stdexcept>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/model/checkpoint_identity.hpp"
#include "engine/outputs/outputs.hpp"
#include "io/checkpoint_file.hpp"

namespace fdem {

Restart load_restart(Domain& domain, const PreparedCase& p, const std::string& path) {
  Restart r;
  io::CheckpointData data;
  std::exception_ptr failure;
  try {
    data = io::read_checkpoint_file(path);
    check_fits(data, p, path);
    std::vector<const char*> keys = {kExodusDigests, kHistoryDigests};
    if (!p.model.ce4.empty()) keys.push_back(kFragmentDigests);
    for (const char* key : keys) {
      const auto it = data.text.find(key);
      try {
        if (it == data.text.end()) throw std::invalid_argument("missing");
        r.digests[key] = io::parse_digests(it->second);
      } catch (const std::invalid_argument&) {
        throw InputError("checkpoint '" + path + "' has no readable '" + key + "' attribute");
      }
    }
    domain.load(data, path);
    const Solver& solver = domain.solver();
    if (solver.steps_done() >= p.steps)
      throw InputError("checkpoint '" + path + "' is at step " + std::to_string(solver.steps_done()) + " (t = " +
                       format_number(solver.time()) + " s), and the case ends at step " + std::to_string(p.steps) +
                       ": extend the run with --set time.end=...");
  } catch (...) {
    failure = std::current_exception();
  }
  domain.agree(failure);
  r.worst_energy_error = data.numbers.count("worst_energy_error") ? data.numbers.at("worst_energy_error") : 0;
  return r;
}

}  // namespace fdem
