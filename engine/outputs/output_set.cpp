#include "engine/outputs/output_set.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/outputs/outputs.hpp"

namespace fdem {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPartial = ".partial";

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

// Writes `snap` to `o`; with profiling, books the host time under `what` and the file's name.
void timed_write(ClContext& cl, Output& o, const Snapshot& snap, const char* what) {
  const auto began = std::chrono::steady_clock::now();
  o.write(snap);
  if (cl.profiling())
    cl.add_host_time(std::string(what) + std::filesystem::path(o.path()).filename().string(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
}

}  // namespace

OutputSet::OutputSet(const PreparedCase& p, ClContext& cl, long first_step, bool writes_files)
    : p_(p), cl_(cl), writes_files_(writes_files) {
  const auto& out = p.config.output;
  const bool ce4 = !p.model.ce4.empty();
  const long history_stride =
      out.history_every > 0 ? std::max(1L, std::lround(out.history_every / p.dt)) : std::max(1L, p.steps / 1000);
  const Trigger frames = Trigger::at_steps(frame_steps(out, p.steps, p.dt));
  auto history = history_rows(p, Trigger::every_steps(history_stride, p.steps));
  auto fragments = ce4 ? fragment_frames(p, frames) : nullptr;
  auto exodus = exodus_frames(p, frames, cl);
  std::vector<const Output*> continued = {exodus.get(), history.get()};  // the files a checkpoint lists
  if (fragments) continued.push_back(fragments.get());
  auto checkpoint = checkpoints(p, Trigger::every_seconds(out.checkpoint_every, p.dt, first_step * p.dt), cl, continued);
  // The breaks are read with each history row and checkpoint, and when the run stops.
  if (ce4) outputs_.push_back(break_catalogue(p, Trigger::any_of({&history->trigger(), &checkpoint->trigger()})));
  outputs_.push_back(std::move(history));
  if (fragments) outputs_.push_back(std::move(fragments));
  outputs_.push_back(std::move(exodus));
  checkpoints_ = checkpoint.get();
  outputs_.push_back(std::move(checkpoint));
}

OutputSet::~OutputSet() {
  try {
    records_.drain();
  } catch (...) {  // the run is failing already (the error that matters is on its way)
  }
  const bool remove = open_ && !placed_;
  std::vector<std::string> paths;
  for (const auto& o : outputs_)
    if (o->role() != Output::Role::Checkpoint) paths.push_back(o->path() + kPartial);
  outputs_.clear();  // closes the files
  std::error_code ec;
  if (remove)
    for (const auto& path : paths) fs::remove(path, ec);
}

Needs OutputSet::setup_needs() const {
  Needs n = Need::Masses;  // the history's unbalanced ratio
  if (!p_.model.ce4.empty()) n |= Need::Catalogue;
  return n;
}

void OutputSet::open(const Snapshot& setup) {
  if (!writes_files_) return;
  open_ = true;
  for (const auto& o : outputs_) o->open(o->path() + kPartial, setup);
}

bool OutputSet::resume(const std::map<std::string, std::vector<std::uint64_t>>& earlier,
                       const std::function<bool()>& stopped, std::ostream& info, long step, double time) {
  if (!open_) return true;
  for (const char* key : {kExodusDigests, kHistoryDigests, kFragmentDigests})
    for (const auto& o : outputs_) {
      if (std::string(o->digest_key()) != key) continue;
      if (!fs::exists(o->path())) {
        info << "note: there is no earlier " << o->path() << ": the new one starts at the checkpoint's step " << step
             << " (t = " << format_number(time) << " s)\n";
        continue;
      }
      Trigger& schedule = o->trigger();
      const double dt = p_.dt;
      const io::ResumeCopy copy{earlier.at(key), [&schedule, dt](double t) { return schedule.on_schedule(std::lround(t / dt)); },
                                stopped};
      if (!o->resume(copy)) return false;
    }
  return true;
}

OutputSet::Due OutputSet::due(long step, double time, bool stopping) const {
  Due d;
  for (const auto& o : outputs_)
    if (o->due(step, time) || (stopping && o->needs().has(Need::Breaks))) {
      d.outputs.push_back(o.get());
      d.needs |= o->needs();
    }
  return d;
}

OutputSet::Due OutputSet::at_end() const {
  Due d;
  for (const auto& o : outputs_)
    if (o.get() == checkpoints_ || o->needs().has(Need::Breaks)) d.outputs.push_back(o.get()), d.needs |= o->needs();
  return d;
}

Needs OutputSet::frame_needs() const {
  Needs n;
  for (const auto& o : outputs_)
    if (o->role() == Output::Role::Frame) n |= o->needs();
  return n;
}

void OutputSet::write(const Due& due, Snapshot&& snap) {
  const bool records_only = std::all_of(due.outputs.begin(), due.outputs.end(),
                                        [](const Output* o) { return o->role() == Output::Role::Record; });
  if (!records_only || !open_) return write(due, static_cast<const Snapshot&>(snap));
  auto shared = std::make_shared<const Snapshot>(std::move(snap));
  std::vector<Output*> records = due.outputs;
  for (Output* o : records) o->trigger().passed(shared->time);
  ClContext* cl = &cl_;
  records_.submit([records = std::move(records), shared, cl] {
    for (Output* o : records) timed_write(*cl, *o, *shared, "output write (host wall, record thread): ");
  });
}

void OutputSet::write(const Due& due, const Snapshot& snap) {
  records_.drain();  // the rows before this snapshot's, in order
  bool frame = false;
  for (Output* o : due.outputs) {
    if (o->role() != Output::Role::Record) sync();  // every row up to a frame or checkpoint is on disk
    if (o->role() == Output::Role::Checkpoint) place();  // the files it continues are in place
    if (open_) timed_write(cl_, *o, snap, "output write (host wall): ");
    frame = frame || o->role() == Output::Role::Frame;
    o->trigger().passed(snap.time);
  }
  if (frame) {
    last_frame_step_ = snap.step;
    place();
  }
}

void OutputSet::write_records(const Due& due, const Snapshot& snap) {
  Due records;
  for (Output* o : due.outputs)
    if (o->role() == Output::Role::Record) records.outputs.push_back(o);
  write(records, snap);
}

void OutputSet::write_frame(const Snapshot& snap) {
  Due frames;
  for (const auto& o : outputs_)
    if (o->role() == Output::Role::Frame) frames.outputs.push_back(o.get());
  write(frames, snap);
}

void OutputSet::finish(const Snapshot& last) {
  records_.drain();
  if (!open_) return;
  for (const auto& o : outputs_) o->finish(last);
}

OutputTotals OutputSet::totals() const {
  records_.drain();
  OutputTotals t;
  if (open_)
    for (const auto& o : outputs_) o->add_totals(t);
  return t;
}

const std::string& OutputSet::checkpoint_path() const { return checkpoints_->path(); }

void OutputSet::place() {
  records_.drain();
  if (!open_ || placed_) return;
  placed_ = true;
  for (const auto& o : outputs_) {
    if (o->role() == Output::Role::Checkpoint) continue;
    std::error_code ec;
    fs::rename(o->path() + kPartial, o->path(), ec);
    if (ec) throw OutputError("cannot put " + o->path() + kPartial + " in place of " + o->path() + ": " + ec.message());
    o->moved_to(o->path());
  }
}

void OutputSet::sync() {
  records_.drain();
  if (open_)
    for (const auto& o : outputs_) o->sync();
}

}  // namespace fdem
