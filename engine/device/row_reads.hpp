// The device reads of one history row, queued without waiting and landed by one wait.
//
// A row needs a dozen small arrays back (the energy account's block sums, the contact
// words and flags, the conditions, positions and forces for the columns). Read one after
// the other, each read drains the queue: on a GPU running a small model that is a
// dozen times the launch latency (about 10 µs each) per row. RowReads queues every read
// asynchronously into page-locked host memory (into ordinary memory NVIDIA's driver
// carries an "asynchronous" read out at once, draining the queue all the same), and the
// first value asked for waits once for all of them. The queue is in order, so a read
// queued after a kernel sees that kernel's result, and an array reused by the next
// kernel (OrderedSums' block sums) has been copied before that kernel runs.
#pragma once
#include <cstddef>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"

namespace fdem {

class RowReads {
 public:
  explicit RowReads(ClContext& cl) : cl_(cl) {}
  RowReads(const RowReads&) = delete;
  RowReads& operator=(const RowReads&) = delete;

  // Elements [first, first + count) of `buffer`, read without waiting. The returned
  // function gives them, landing every queued read first if they have not landed yet;
  // it stays valid until begin() is called again.
  template <typename T>
  std::function<std::vector<T>()> read(const compute::buffer& buffer, std::size_t count, std::size_t first = 0) {
    if (count == 0) return [] { return std::vector<T>(); };
    const std::size_t bytes = count * sizeof(T);
    unsigned char* place = reserve(bytes);
    cl_.queue().enqueue_read_buffer_async(buffer, first * sizeof(T), bytes, place);
    pending_ = true;
    return [this, place, count] {
      land();
      std::vector<T> out(count);
      std::memcpy(out.data(), place, count * sizeof(T));
      return out;
    };
  }

  // Waits once for every read queued since begin() (nothing when they have landed).
  void land() {
    if (!pending_) return;
    cl_.finish();
    pending_ = false;
  }

  // A new row: the staging memory is reused from its start (reads of the last row that
  // were never asked for are landed first, so none is still being written). When the
  // last row needed more than the first chunk, that chunk is replaced by one that holds
  // it all.
  void begin() {
    land();
    if (chunks_.size() > 1) {
      std::size_t total = 0;
      for (const auto& c : chunks_) total += c->size();
      chunks_.clear();
      chunks_.push_back(std::make_unique<PinnedHost<unsigned char>>(cl_, total));
    }
    chunk_ = 0;
    used_ = 0;
  }

 private:
  static constexpr std::size_t kAlign = 64;
  // Room for `bytes` in the current chunk, or in a new one (a read already queued keeps
  // writing into its own chunk, so chunks are added, never moved).
  unsigned char* reserve(std::size_t bytes) {
    const std::size_t start = (used_ + kAlign - 1) / kAlign * kAlign;
    if (!chunks_.empty() && start + bytes <= chunks_[chunk_]->size()) {
      used_ = start + bytes;
      return chunks_[chunk_]->data() + start;
    }
    const std::size_t size = std::max<std::size_t>({bytes, std::size_t(1) << 16, chunks_.empty() ? 0 : 2 * chunks_.back()->size()});
    chunks_.push_back(std::make_unique<PinnedHost<unsigned char>>(cl_, size));
    chunk_ = chunks_.size() - 1;
    used_ = bytes;
    return chunks_[chunk_]->data();
  }

  ClContext& cl_;
  std::vector<std::unique_ptr<PinnedHost<unsigned char>>> chunks_;
  std::size_t chunk_ = 0, used_ = 0;
  bool pending_ = false;
};

}  // namespace fdem
