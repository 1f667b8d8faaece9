// History rows (engine/outputs/outputs.hpp): one row of HistoryTable's columns per write.
#include "engine/outputs/history_table.hpp"
#include "engine/outputs/outputs.hpp"
#include "io/history_writer.hpp"

namespace fdem {

namespace {

// How old the history file's last sync may get before a row syncs it (HistoryWriter): the
// rows a killed run can lose, beyond those after its last checkpoint or frame.
constexpr double kHistorySyncSeconds = 0.5;

class HistoryRows : public Output {
 public:
  HistoryRows(const PreparedCase& p, Trigger trigger)
      : Output(p.history_path, std::move(trigger)), p_(p), probes_(p.probes) {}
  Role role() const override { return Role::Record; }
  Needs needs() const override { return HistoryTable::needs(p_.model, probes_); }
  void open(const std::string& partial, const Snapshot& setup) override {
    table_ = std::make_unique<HistoryTable>(p_.model, setup.masses, probes_);
    file_ = std::make_unique<io::HistoryWriter>(partial, p_.config.title, table_->variables());
    // Rows sync at most every kHistorySyncSeconds, and always before a frame or a
    // checkpoint: a killed run keeps every row up to its last checkpoint, which is
    // what a restart continues from (docs/case-format.md, "history").
    file_->set_sync_interval(kHistorySyncSeconds);
  }
  void write(const Snapshot& snap) override {
    HistoryRow row(snap);
    last_row_ = table_->values(row);
    file_->append(snap.time, last_row_);
  }
  bool resume(const io::ResumeCopy& copy) override { return io::copy_history_rows(path(), *file_, copy) >= 0; }
  const char* digest_key() const override { return kHistoryDigests; }
  std::vector<std::uint64_t> digests() const override { return file_->row_digests(); }
  void moved_to(const std::string& path) override { file_->moved_to(path); }
  void sync() override { file_->sync(); }
  void finish(const Snapshot&) override { file_->close(); }
  void add_totals(OutputTotals& t) const override {
    t.last_row = last_row_;
    t.kinetic_column = table_->index("kinetic_energy");
    t.unbalanced_column = table_->index("unbalanced_ratio");
  }

 private:
  const PreparedCase& p_;
  const PointProbes probes_;
  std::unique_ptr<HistoryTable> table_;
  std::unique_ptr<io::HistoryWriter> file_;
  std::vector<double> last_row_;
};

}  // namespace

std::unique_ptr<Output> history_rows(const PreparedCase& p, Trigger trigger) {
  return std::make_unique<HistoryRows>(p, std::move(trigger));
}

}  // namespace fdem
