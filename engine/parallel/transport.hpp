// How the ranks of a split run talk (ARCHITECTURE.md, "Scale-out"): messages of bytes
// between two ranks, delivered in the order they were posted, and the few collectives
// built on them. Two implementations: MpiTransport (MPI_COMM_WORLD; builds with
// FDEM_HAVE_MPI) for `mpirun -np N fdem run`, and InProcessHub's transports, which
// deliver through memory so that tests can step several ranks in one process.
//
// Every rank calls the same operations in the same order (the step loop is the same on
// every rank); the collectives rely on it. post() never waits; receive() waits for the
// message (MPI) or takes it from the mailbox (in process: the sender must have posted
// it already, so an in-process caller posts on every rank before it receives on any).
#pragma once
#include <cstdint>
#include <cstring>
#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace fdem {

using Bytes = std::vector<char>;

template <class T>
Bytes to_bytes(const std::vector<T>& v) {
  Bytes b(v.size() * sizeof(T));
  if (!v.empty()) std::memcpy(b.data(), v.data(), b.size());
  return b;
}
template <class T>
std::vector<T> from_bytes(const Bytes& b) {
  std::vector<T> v(b.size() / sizeof(T));
  if (!v.empty()) std::memcpy(v.data(), b.data(), v.size() * sizeof(T));
  return v;
}

class Transport {
 public:
  virtual ~Transport() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Sends `data` to rank `to` (≠ rank()); never waits.
  virtual void post(int to, Bytes data) = 0;
  // The next message from rank `from` (≠ rank()), in posting order.
  virtual Bytes receive(int from) = 0;
  // As post, from where `data` lies: the caller keeps it unchanged until complete()
  // (MPI: no copy). By default a copy through post().
  virtual void post_from(int to, const Bytes& data) { post(to, data); }
  // As receive, into `out`, whose buffer is reused when large enough.
  virtual void receive_into(int from, Bytes& out) { out = receive(from); }
  // Waits until the messages this rank posted may be reused (MPI: their requests done).
  virtual void complete() {}
  // Ends every rank at once with `code` (MPI_Abort): the last resort when ranks disagree
  // on where they are, so that none waits for ever. In process: throws.
  [[noreturn]] virtual void abort(int code, const std::string& message) = 0;

  // Collectives (every rank calls them, in the same order). Rank 0 gets every rank's
  // `data` in rank order; the others get an empty list.
  std::vector<Bytes> gather(Bytes data);
  // gather for large messages repeated at every history row: `data` is sent from where it
  // lies and rank 0 receives rank r's into others[r] (r ≥ 1; its own stays in `data`),
  // into the buffers of the last call. A fresh buffer of tens of MB is a fresh mapping
  // (malloc), whose page faults cost more than the copy (the split energy account).
  void gather_into(const Bytes& data, std::vector<Bytes>& others);
  // Rank 0's `data` on every rank.
  Bytes broadcast(Bytes data);
  // The smallest and largest of one value per rank, on every rank.
  int64_t min(int64_t value);
  int64_t max(int64_t value);
};

// Transports for ranks stepped in one process (tests). Each rank's transport delivers
// into the others' mailboxes; collectives need threads, so the emulation uses post and
// receive only.
class InProcessHub {
 public:
  explicit InProcessHub(int ranks);
  Transport& rank(int r) { return *ranks_[r]; }

 private:
  class Rank;
  std::vector<std::deque<Bytes>> box_;  // box_[from * n + to]
  std::vector<std::unique_ptr<Transport>> ranks_;
};

#ifdef FDEM_HAVE_MPI
// MPI_COMM_WORLD. The process must have called MPI_Init (MpiSession).
class MpiTransport : public Transport {
 public:
  MpiTransport();
  ~MpiTransport() override;
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void post(int to, Bytes data) override;
  Bytes receive(int from) override;
  void post_from(int to, const Bytes& data) override;
  void receive_into(int from, Bytes& out) override;
  void complete() override;
  [[noreturn]] void abort(int code, const std::string& message) override;

 private:
  int rank_ = 0, size_ = 1;
  struct Pending;
  std::vector<std::unique_ptr<Pending>> pending_;
};
#endif

// MPI_Init on construction and MPI_Finalize on destruction when the process was started
// by an MPI launcher with this build's MPI; otherwise nothing. `active()`: MPI is up.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  bool active() const { return active_; }
  int size() const { return size_; }
  int rank() const { return rank_; }
  // The rank within its node (OMPI_COMM_WORLD_LOCAL_RANK, MPI_COMM_TYPE_SHARED), for
  // picking the node's GPU.
  int local_rank() const { return local_rank_; }

 private:
  bool active_ = false;
  int size_ = 1, rank_ = 0, local_rank_ = 0;
};

// Whether a launcher started this process as one of several ranks (OMPI_COMM_WORLD_SIZE
// or PMI_SIZE above 1), and how many; 1 when not.
int launcher_ranks(std::string* variable = nullptr);

}  // namespace fdem
