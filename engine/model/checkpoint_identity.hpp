// Which run a checkpoint belongs to. Each checkpoint carries its format version, the build's
// precision, the case's settings and a hash of the mesh; a restart is refused (InputError,
// exit 2) when any of them does not fit, naming what differs. Only time.end (time.steps)
// and output.* may change between a checkpoint and its restart.
#pragma once
#include <string>

#include "engine/model/prepared_case.hpp"
#include "io/checkpoint_file.hpp"

namespace fdem {

// Writes the identity into `data.text` (format_version, precision, settings, mesh_hash).
void stamp_checkpoint(io::CheckpointData& data, const PreparedCase& p);
// Throws InputError naming `path` and what differs when `data` is not a checkpoint of `p`.
void check_fits(const io::CheckpointData& data, const PreparedCase& p, const std::string& path);

}  // namespace fdem
