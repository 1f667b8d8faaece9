// Checkpoints (engine/outputs/outputs.hpp): the whole state a run continues from, with
// the case's identity and the digests of the records the other files hold.
#include <chrono>

#include "engine/model/checkpoint_identity.hpp"
#include "engine/outputs/outputs.hpp"
#include "io/checkpoint_file.hpp"

namespace fdem {

namespace {

class Checkpoints : public Output {
 public:
  Checkpoints(const PreparedCase& p, Trigger trigger, ClContext& cl, std::vector<const Output*> continued)
      : Output(checkpoint_path(p), std::move(trigger)), p_(p), cl_(cl), continued_(std::move(continued)) {}
  Role role() const override { return Role::Checkpoint; }
  Needs needs() const override { return Need::State | Need::GoodCopy; }
  void open(const std::string&, const Snapshot&) override {}  // each checkpoint replaces the last whole
  void write(const Snapshot& snap) override {
    const auto began = std::chrono::steady_clock::now();
    io::CheckpointData data = snap.state;
    stamp_checkpoint(data, p_);
    data.text["device"] = cl_.description();
    data.text["case_path"] = p_.config.path;
    data.text["title"] = p_.config.title;
    data.text["case_text"] = p_.config.text;
    data.numbers["time"] = snap.time;
    data.numbers["dt"] = p_.dt;
    data.numbers["worst_energy_error"] = snap.worst_energy_error;
    data.integers["broken_ce4"] = snap.broken_ce4;
    // The files this checkpoint continues are in place (OutputSet), and it lists what they hold.
    for (const Output* o : continued_) data.text[o->digest_key()] = io::digests_text(o->digests());
    io::write_checkpoint_file(path(), data);
    seconds_ = snap.state_seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  }
  void moved_to(const std::string&) override {}
  void finish(const Snapshot&) override {}
  void add_totals(OutputTotals& t) const override { t.checkpoint_seconds = seconds_; }

 private:
  const PreparedCase& p_;
  ClContext& cl_;
  std::vector<const Output*> continued_;
  double seconds_ = 0;
};

}  // namespace

std::unique_ptr<Output> checkpoints(const PreparedCase& p, Trigger trigger, ClContext& cl,
                                    std::vector<const Output*> continued) {
  return std::make_unique<Checkpoints>(p, std::move(trigger), cl, std::move(continued));
}

}  // namespace fdem
