// Continuing the output of a restarted run: the frames and rows an earlier run wrote up to
// the checkpoint's time are copied into the new writers (later ones, written after the
// checkpoint before a crash, are dropped, so no time appears twice).
#pragma once
#include <functional>
#include <string>

#include "io/exodus_writer.hpp"
#include "io/fragment_writer.hpp"
#include "io/history_writer.hpp"

namespace fdem::io {

// Copies the rows of history file `from` up to time t_max whose time `keep` accepts into
// `to`, variable by name (a variable `from` lacks gets NaN). Returns the rows copied.
// OutputError when `from` cannot be read.
int copy_history_rows(const std::string& from, HistoryWriter& to, double t_max,
                      const std::function<bool(double)>& keep);

// Copies the frames of Exodus file `from` up to time t_max whose time `keep` accepts into
// `to` (the same mesh and variables). Returns the frames copied.
int copy_exodus_frames(const std::string& from, ExodusWriter& to, double t_max,
                       const std::function<bool(double)>& keep);

// Copies the frames of fragments file `from` up to time t_max whose time `keep` accepts
// into `to` (frames renumbered from 0, as the copied Exodus frames). Returns the frames copied.
int copy_fragment_frames(const std::string& from, FragmentWriter& to, double t_max,
                         const std::function<bool(double)>& keep);

}  // namespace fdem::io
