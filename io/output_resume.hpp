// Continuing the output of a restarted run: the frames and rows an earlier run wrote up to
// its checkpoint are checked against the checkpoint and copied into the new writers (later
// ones, written after the checkpoint before a crash, are dropped, so no time appears twice).
//
// The checkpoint lists the digest of every record each file held when it was written
// (digests_text; the writers keep them: RecordDigest). Each of those records is read back
// and compared before anything is copied: a file that was cut short, zeroed in part or
// otherwise changed is refused (InputError, exit 2) naming the file and the first record
// that differs, never copied as garbage.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "io/exodus_writer.hpp"
#include "io/fragment_writer.hpp"
#include "io/history_writer.hpp"

namespace fdem::io {

// Record digests as a checkpoint stores them: 16 hex digits each, separated by spaces.
std::string digests_text(const std::vector<std::uint64_t>& digests);
// Throws std::invalid_argument for text that digests_text did not write.
std::vector<std::uint64_t> parse_digests(const std::string& text);

// What the copies below take: the digests of the records `from` held at the checkpoint
// (its first written.size() records), which of them to copy (by time: the continuing run's
// schedule), and `stopped`, asked between records (a signal): when it says so the copy
// ends early and returns -1. Each returns the records copied. InputError naming `from` and
// the record when one of the first written.size() records is missing, unreadable or not
// the one the run wrote; records after them are dropped.
struct ResumeCopy {
  std::vector<std::uint64_t> written;
  std::function<bool(double)> keep;
  std::function<bool()> stopped = [] { return false; };
};

// History rows, copied variable by name (a variable `from` lacks gets NaN).
int copy_history_rows(const std::string& from, HistoryWriter& to, const ResumeCopy& copy);
// Exodus frames (the same mesh and variables).
int copy_exodus_frames(const std::string& from, ExodusWriter& to, const ResumeCopy& copy);
// Fragments frames (renumbered from 0, as the copied Exodus frames).
int copy_fragment_frames(const std::string& from, FragmentWriter& to, const ResumeCopy& copy);

}  // namespace fdem::io
