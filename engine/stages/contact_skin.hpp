// Skin rebuild test for contact detection (the test itself runs in cl_kernels/integrate.cl).
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "engine/device/checkpoint.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/stages/monitor_ring.hpp"

namespace fdem {

// Decides when contact detection must run again with a skin: a couple can only appear
// once some node has moved more than half the skin since the last detection. The test
// runs on the device every step, inside the previous step's integration (integrate.cl;
// Integrate built with this skin), into the MonitorRing's kSlots slots; the host reads
// the ring kBatch slots at a time, asynchronously, and looks at a batch kBatch steps after it
// was read, so a test is seen up to kSlots − 1 steps late and the host never waits for
// the device in the step loop. The nodes can move a little in those steps, so the test
// asks for a margin of 2 × kSlots × (largest speed seen) × Δt on top (2: room for the
// speed to double in that time). When that margin would exceed a quarter of the skin
// (very fast nodes or a thin skin), and until a first batch has told the speeds, each
// step waits for its own test instead (exact).
class ContactSkin {
 public:
  static constexpr unsigned kSlots = MonitorRing::kSlots, kBatch = MonitorRing::kBatch;

  // Reads the tests (and the activation's join flags) from `ring`.
  // node_owned (a split run; empty: every node): the test takes only these nodes, and
  // set_reduce() makes every rank see the same readings.
  ContactSkin(ClContext& cl, DeviceArrays& arrays, MonitorRing& ring, double skin, double dt,
              const std::vector<char>& node_owned = {});
  // The arrays the constructor allocates.
  static MemoryPlan plan(size_t nodes, bool owned = false) {
    MemoryPlan p;
    p.add("position_at_build", nodes * sizeof(real2));
    if (owned) p.add("skin node_owned", std::max<size_t>(nodes, 1) * sizeof(cl_uchar));
    return p;
  }
  const compute::buffer* owned_mask() const { return owned_ ? &node_owned_ : nullptr; }
  // A split run: called with `count` consecutive ring slots (RING_WORDS words each) as
  // this rank read them, it must leave in words RING_MOVED, RING_SPEED and RING_JOINED
  // the largest over all ranks (collective: every rank calls it at the same steps, since
  // every rank then decides the same). The pool word stays this rank's own.
  void set_reduce(std::function<void(cl_uint* words, unsigned count)> reduce) { reduce_ = std::move(reduce); }
  // An adaptive skin (`skin = "auto"`, one rank): before each detection, choose() picks
  // the skin that detection and the list until the next one use, from the largest node
  // speed the tests have shown and the cost model below; `box_side` is the model's mean
  // edge (the typical triangle's box), `triangles` its count. Off: the skin stays fixed.
  void adapt(double box_side, size_t triangles);
  bool adaptive() const { return adaptive_; }
  // The skin for the detection about to run, given `listed` couples in the list now
  // (found with skin()). Minimises a step's cost in units of one listed couple's work a
  // step (its classification):
  //   J(s) = D(s) / n(s) + L(s),   n(s) = s / (2 v Δt)   steps until a node at the largest
  //   speed v crosses half the skin;  L(s) = listed · ((b + s) / (b + skin()))²  couples
  //   (boxes of side b grown by s);  D(s) = kDetectionFixed + kDetectionPerTriangle · T +
  //   kDetectionPerCouple · L(s), a detection's cost (measured on the H200: see
  //   docs/performance-notes.md, Session 9).
  // Over a log grid of 65 skins within [skin() / 2, 2 skin()] ∩ [b / 1000, b]: a skin at
  // most doubles or halves from one detection to the next, so one odd reading of the speed
  // cannot throw it far. With no speed seen yet it keeps skin(). Deterministic: the speeds
  // and counts are the device's, so the run stays bitwise reproducible. Returns skin().
  double choose(size_t listed);
  double skin() const { return 2.0 * half_skin_; }
  // Couple-steps (see choose) a detection costs: fixed (launches, the count read), per
  // triangle (boxes, binning, counting), per couple listed (writing, carrying).
  static constexpr double kDetectionFixed = 1.0e7, kDetectionPerTriangle = 60.0, kDetectionPerCouple = 4.0;
  // Remembers the current positions as those of the last detection. Never waits.
  void mark();
  // The integration that ends step − 1 has enqueued the test of `step` (positions then
  // against those at the last mark()). Never waits.
  void measured(long step);
  // What the list needs at `step`, from the tests read so far: nothing; the couples of
  // triangles that joined the candidates since the joins it covers (Joined: the list can
  // be extended, ContactDetection::extend_joined); or a new detection (Moved: some node
  // may have moved more than half the skin). Waits only for a batch read kBatch steps
  // ago, or for its own test in the exact mode above.
  enum class Due { Nothing, Joined, Moved };
  Due rebuild_due(long step);
  // The list holds the couples of every join up to the activation of `step` (a detection
  // or an extension at that step): joins flagged in slots of steps up to it are done.
  void joins_covered(long step) { joins_covered_step_ = step; }
  compute::buffer& position_at_build() { return at_build_; }
  MonitorRing& ring() { return ring_; }
  long synchronous_checks() const { return synchronous_; }
  // The smallest and largest skin choose() has picked (0 before it first ran) [m].
  double smallest_skin() const { return smallest_skin_; }
  double largest_skin() const { return largest_skin_; }
  // The most contact history pool rows taken that the ring has shown since the last
  // mark() (word RING_POOL, written by ContactForces' clear kernel; up to kSlots − 1 steps
  // late), for ContactForces::ensure_pool.
  size_t pool_rows_seen() const { return pool_seen_; }
  // The most rows taken in one step in the last batch read (consecutive slots), for the
  // margin of ensure_pool.
  size_t pool_rows_per_step() const { return pool_rate_; }
  // Positions at the last detection, the device ring and the host's view of it (the
  // decisions of the steps to come depend on all of them), for checkpoints. Waits.
  void save_state(StateWriter& out);
  void load_state(StateReader& in);

 private:
  Due decide(unsigned slot, bool exact);
  Due decide_batch();

  ClContext& cl_;
  DeviceArrays& arrays_;
  double half_skin_, dt_;
  bool adaptive_ = false;
  double box_side_ = 0;
  size_t triangles_ = 0;
  double smallest_skin_ = 0, largest_skin_ = 0;  // the skins choose() picked [m]
  MonitorRing& ring_;
  compute::buffer at_build_, node_owned_;
  bool owned_ = false;
  std::function<void(cl_uint*, unsigned)> reduce_;
  PinnedHost<cl_uint> host_;                   // kSlots × RING_WORDS words, filled by async reads
  compute::event batch_read_;                  // the last batch read (slots batch_first_ …)
  unsigned batch_first_ = 0;
  bool batch_pending_ = false, speed_known_ = false;
  std::array<long, kSlots> generation_of_{};   // mark() count when the slot was measured
  std::array<long, kSlots> step_of_{};         // the step whose test and joins the slot holds
  long joins_covered_step_ = -1;               // see joins_covered()
  long generation_ = 0;
  double largest_speed_ = 0;                   // from the latest test read [m/s]
  size_t pool_seen_ = 0;                       // see pool_rows_seen()
  size_t pool_rate_ = 0;                       // see pool_rows_per_step()
  long synchronous_ = 0;
};

}  // namespace fdem
