#include "engine/outputs/record_thread.hpp"

#include <csignal>
#include <pthread.h>

namespace fdem {

RecordThread::~RecordThread() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void RecordThread::rethrow_failure() {
  if (!failure_) return;
  std::exception_ptr failure = failure_;
  failure_ = nullptr;
  tasks_.clear();  // the rows after a failed one are not written
  std::rethrow_exception(failure);
}

void RecordThread::submit(std::function<void()> task) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!thread_.joinable()) thread_ = std::thread([this] { loop(); });
  changed_.wait(lock, [this] { return tasks_.size() < kQueued || failure_; });
  rethrow_failure();
  tasks_.push_back(std::move(task));
  lock.unlock();
  changed_.notify_all();
}

void RecordThread::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  // A failure clears the queue (loop), so this also ends once a failed task has returned.
  changed_.wait(lock, [this] { return tasks_.empty() && !running_; });
  rethrow_failure();
}

void RecordThread::loop() {
  // The stop signals (fdem run's SIGTERM, SIGINT, SIGUSR1) go to the main thread, which
  // checks their flag between steps; this thread's file writes are not interrupted.
  sigset_t stops;
  sigemptyset(&stops);
  for (int signal : {SIGTERM, SIGINT, SIGUSR1}) sigaddset(&stops, signal);
  pthread_sigmask(SIG_BLOCK, &stops, nullptr);
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return !tasks_.empty() || stop_; });
    if (tasks_.empty()) return;  // stopping, and nothing left to write
    std::function<void()> task = std::move(tasks_.front());
    tasks_.pop_front();
    running_ = true;
    lock.unlock();
    std::exception_ptr failure;
    try {
      task();
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    running_ = false;
    if (failure && !failure_) failure_ = failure;
    if (failure_) tasks_.clear();
    changed_.notify_all();
  }
}

}  // namespace fdem
