// The outputs a run writes (engine/outputs/output.hpp), one file each. A new output is a
// class in its own .cpp here and one line in OutputSet's constructor (ARCHITECTURE.md,
// "The run": a worked example).
#pragma once
#include <memory>

#include "engine/device/cl_context.hpp"
#include "engine/outputs/output.hpp"
#include "engine/model/prepared_case.hpp"

namespace fdem {

// Exodus frames: displacements, velocities, contact forces; stresses, CE4 state, pieces.
std::unique_ptr<Output> exodus_frames(const PreparedCase& p, Trigger trigger, ClContext& cl);
// The pieces of each frame (models with CE4s): NAME_fragments.nc.
std::unique_ptr<Output> fragment_frames(const PreparedCase& p, Trigger trigger);
// History rows (HistoryTable's columns).
std::unique_ptr<Output> history_rows(const PreparedCase& p, Trigger trigger);
// The break catalogue and its events (models with CE4s): NAME_events.nc.
std::unique_ptr<Output> break_catalogue(const PreparedCase& p, Trigger trigger);
// Checkpoints: the whole state, and the digests of the records `continued` hold.
std::unique_ptr<Output> checkpoints(const PreparedCase& p, Trigger trigger, ClContext& cl,
                                    std::vector<const Output*> continued);

// The checkpoint's attributes with the digests of the records each file held when it was
// written (io/output_resume.hpp): what a restart checks the earlier files against.
constexpr const char* kExodusDigests = "exodus_frame_digests";
constexpr const char* kHistoryDigests = "history_row_digests";
constexpr const char* kFragmentDigests = "fragment_frame_digests";

}  // namespace fdem
