// The thread that writes the records (history rows, break events) while the device steps
// on (ARCHITECTURE.md, "The run"). The main thread reads a snapshot, hands its records to
// this thread and enqueues the next steps at once, so the host's row work (the columns,
// the netCDF append) overlaps the device's stepping instead of leaving it idle.
//
// One task at a time, in the order submitted: a file's rows stay in order. netCDF and HDF5
// are not thread-safe, so OutputSet drains this thread before any other file call (a frame,
// a checkpoint, a sync, closing); between drains only this thread touches the files.
// A task that throws keeps its exception; the next submit() or drain() rethrows it on the
// main thread (the run then stops with that error, as if the write had been synchronous).
#pragma once
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace fdem {

class RecordThread {
 public:
  RecordThread() = default;
  ~RecordThread();  // waits for the queued tasks (their failure is dropped) and joins
  RecordThread(const RecordThread&) = delete;
  RecordThread& operator=(const RecordThread&) = delete;

  // Queues `task`; waits first while `kQueued` tasks are already waiting (a slow disk
  // holds the stepping back rather than piling up snapshots). Rethrows an earlier failure.
  void submit(std::function<void()> task);
  // Waits until every submitted task has run; rethrows the first failure.
  void drain();

 private:
  static constexpr size_t kQueued = 1;
  void loop();
  void rethrow_failure();  // with mutex_ held

  std::thread thread_;  // started by the first submit()
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> tasks_;
  bool running_ = false;  // a task is being run
  bool stop_ = false;
  std::exception_ptr failure_;
};

}  // namespace fdem
