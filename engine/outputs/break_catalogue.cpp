// The break catalogue (engine/outputs/outputs.hpp): every CE4 break, appended as the reads
// bring them (a resumed run starts from the catalogue its checkpoint carries, so breaks
// written after the checkpoint before a crash are dropped like rows and frames), grouped
// into events at the end.
#include "engine/outputs/fracture_events.hpp"
#include "engine/outputs/outputs.hpp"
#include "io/events_writer.hpp"

namespace fdem {

namespace {

class BreakCatalogue : public Output {
 public:
  BreakCatalogue(const PreparedCase& p, Trigger trigger) : Output(p.events_path, std::move(trigger)), p_(p) {}
  Role role() const override { return Role::Record; }
  Needs needs() const override { return Need::Breaks; }
  void open(const std::string& partial, const Snapshot& setup) override {
    file_ = std::make_unique<io::EventsWriter>(partial, p_.config.title, !p_.model.ce4_grain_boundary.empty());
    write(setup);  // the catalogue so far
  }
  void write(const Snapshot& snap) override {
    file_->append(snap.breaks);
    all_.insert(all_.end(), snap.breaks.begin(), snap.breaks.end());
  }
  void moved_to(const std::string& path) override { file_->moved_to(path); }
  void finish(const Snapshot& last) override {
    write(last);
    const io::EventRule rule = event_rule(p_.model, p_.config.output.events_distance, p_.config.output.events_window);
    events_ = group_events(all_, rule);
    file_->finish(all_, events_, rule);
  }
  void add_totals(OutputTotals& t) const override { t.breaks = all_.size(), t.events = events_.size(); }

 private:
  const PreparedCase& p_;
  std::unique_ptr<io::EventsWriter> file_;
  std::vector<io::BreakRecord> all_;
  std::vector<io::EventRecord> events_;
};

}  // namespace

std::unique_ptr<Output> break_catalogue(const PreparedCase& p, Trigger trigger) {
  return std::make_unique<BreakCatalogue>(p, std::move(trigger));
}

}  // namespace fdem
