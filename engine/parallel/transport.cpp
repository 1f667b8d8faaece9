#include "engine/parallel/transport.hpp"

#include <algorithm>
#include <cstdlib>
#include <iostream>

#include "base/errors.hpp"
#ifdef FDEM_HAVE_MPI
#include <mpi.h>
#endif

namespace fdem {

std::vector<Bytes> Transport::gather(Bytes data) {
  std::vector<Bytes> all;
  if (rank() != 0) {
    post(0, std::move(data));
    complete();
    return all;
  }
  all.resize(size());
  all[0] = std::move(data);
  for (int r = 1; r < size(); ++r) all[r] = receive(r);
  return all;
}

void Transport::gather_into(const Bytes& data, std::vector<Bytes>& others) {
  if (rank() != 0) {
    post_from(0, data);
    complete();
    return;
  }
  others.resize(size());
  for (int r = 1; r < size(); ++r) receive_into(r, others[r]);
}

Bytes Transport::broadcast(Bytes data) {
  if (rank() != 0) return receive(0);
  for (int r = 1; r < size(); ++r) post(r, data);
  complete();
  return data;
}

int64_t Transport::min(int64_t value) {
  const auto all = gather(to_bytes(std::vector<int64_t>{value}));
  int64_t m = value;
  for (const auto& b : all) m = std::min(m, from_bytes<int64_t>(b).at(0));
  return from_bytes<int64_t>(broadcast(to_bytes(std::vector<int64_t>{m}))).at(0);
}

int64_t Transport::max(int64_t value) { return -min(-value); }

class InProcessHub::Rank : public Transport {
 public:
  Rank(InProcessHub& hub, int rank) : hub_(hub), rank_(rank) {}
  int rank() const override { return rank_; }
  int size() const override { return static_cast<int>(hub_.ranks_.size()); }
  void post(int to, Bytes data) override { hub_.box_[rank_ * size() + to].push_back(std::move(data)); }
  Bytes receive(int from) override {
    auto& box = hub_.box_[from * size() + rank_];
    if (box.empty())
      throw std::logic_error("in-process transport: rank " + std::to_string(rank_) + " receives from rank " +
                             std::to_string(from) + ", which has posted nothing (post on every rank first)");
    Bytes b = std::move(box.front());
    box.pop_front();
    return b;
  }
  [[noreturn]] void abort(int, const std::string& message) override { throw std::logic_error(message); }

 private:
  InProcessHub& hub_;
  int rank_;
};

InProcessHub::InProcessHub(int ranks) : box_(static_cast<size_t>(ranks) * ranks) {
  for (int r = 0; r < ranks; ++r) ranks_.push_back(std::make_unique<Rank>(*this, r));
}

int launcher_ranks(std::string* variable) {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* value = std::getenv(name);
    if (value && std::atoi(value) > 1) {
      if (variable) *variable = name;
      return std::atoi(value);
    }
  }
  return 1;
}

#ifdef FDEM_HAVE_MPI
struct MpiTransport::Pending {
  Bytes data;
  MPI_Request request;
};

MpiTransport::MpiTransport() {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiTransport::~MpiTransport() {
  try {
    complete();
  } catch (...) {
  }
}

namespace {
constexpr int kTag = 15;
}

void MpiTransport::post(int to, Bytes data) {
  auto p = std::make_unique<Pending>();
  p->data = std::move(data);
  MPI_Isend(p->data.data(), static_cast<int>(p->data.size()), MPI_BYTE, to, kTag, MPI_COMM_WORLD, &p->request);
  pending_.push_back(std::move(p));
}

Bytes MpiTransport::receive(int from) {
  MPI_Status status;
  MPI_Probe(from, kTag, MPI_COMM_WORLD, &status);
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  Bytes b(static_cast<size_t>(count));
  MPI_Recv(b.data(), count, MPI_BYTE, from, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return b;
}

void MpiTransport::post_from(int to, const Bytes& data) {
  auto p = std::make_unique<Pending>();  // no data of its own: the caller keeps it
  MPI_Isend(data.data(), static_cast<int>(data.size()), MPI_BYTE, to, kTag, MPI_COMM_WORLD, &p->request);
  pending_.push_back(std::move(p));
}

void MpiTransport::receive_into(int from, Bytes& out) {
  MPI_Status status;
  MPI_Probe(from, kTag, MPI_COMM_WORLD, &status);
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  out.resize(static_cast<size_t>(count));
  MPI_Recv(out.data(), count, MPI_BYTE, from, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

void MpiTransport::complete() {
  for (auto& p : pending_) MPI_Wait(&p->request, MPI_STATUS_IGNORE);
  pending_.clear();
}

void MpiTransport::abort(int code, const std::string& message) {
  std::cerr << message << std::flush;
  MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

MpiSession::MpiSession(int* argc, char*** argv) {
  // Only under a real launch (Open MPI's PMIx or ORTE contact, MPICH's PMI): MPI_Init in a
  // process that merely has OMPI_COMM_WORLD_SIZE set would wait for a launcher.
  if (!std::getenv("PMIX_RANK") && !std::getenv("OMPI_MCA_orte_hnp_uri") && !std::getenv("PMI_RANK")) return;
  // FUNNELED: the outputs' record thread (engine/outputs/record_thread.hpp) writes files
  // beside the main thread and never calls MPI.
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  active_ = true;
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  MPI_Comm_rank(node, &local_rank_);
  MPI_Comm_free(&node);
}

MpiSession::~MpiSession() {
  if (active_) MPI_Finalize();
}
#else
MpiSession::MpiSession(int*, char***) {}
MpiSession::~MpiSession() {}
#endif

}  // namespace fdem
