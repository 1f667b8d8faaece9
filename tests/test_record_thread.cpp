// The outputs' record thread (engine/outputs/record_thread.hpp): rows in order, a failed
// write reaches the main thread, and nothing is left running when it goes away.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "engine/outputs/record_thread.hpp"

using fdem::RecordThread;

TEST_SUITE("restart") {

TEST_CASE("record thread: tasks run in order, away from the caller, and drain() waits for them") {
  RecordThread records;
  std::vector<int> order;  // touched only by the record thread until drain() returns
  std::atomic<bool> elsewhere{true};
  const auto caller = std::this_thread::get_id();
  for (int i = 0; i < 50; ++i)
    records.submit([&order, &elsewhere, caller, i] {
      if (std::this_thread::get_id() == caller) elsewhere = false;
      if (i % 7 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a slow row
      order.push_back(i);
    });
  records.drain();
  REQUIRE(order.size() == 50);
  for (int i = 0; i < 50; ++i) CHECK(order[i] == i);
  CHECK(elsewhere);
  records.drain();  // idle: returns at once
}

TEST_CASE("record thread: a failed write is rethrown once, on the caller, and later rows are dropped") {
  RecordThread records;
  std::atomic<int> written{0};
  records.submit([&written] { ++written; });
  records.submit([] { throw std::runtime_error("cannot append to out/x_history.nc: disk full"); });
  bool dropped_or_refused = false;
  try {
    records.submit([&written] { written += 100; });  // queued behind the failure, or refused by it
    records.drain();
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()).find("disk full") != std::string::npos);
    dropped_or_refused = true;
  }
  CHECK(dropped_or_refused);
  CHECK(written == 1);  // the row after the failed one is not written
  records.drain();      // the failure was handed over: nothing more to throw
  records.submit([&written] { ++written; });
  records.drain();
  CHECK(written == 2);
}

TEST_CASE("record thread: destroyed with rows queued, it writes them and joins") {
  std::atomic<int> written{0};
  {
    RecordThread records;
    for (int i = 0; i < 3; ++i)
      records.submit([&written] {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        ++written;
      });
  }
  CHECK(written == 3);
}

}  // TEST_SUITE
