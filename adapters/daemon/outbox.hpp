#pragma once
// Writes to DDS on a thread of its own, so that a write that waits holds up
// no thread that drives a bus. A reliable write may wait for up to its
// max_blocking_time: a keep-all writer's while readers have not acknowledged
// enough of what it wrote, any writer's while a reader in the same process
// has no room.
//
// Jobs run in the order they were posted, at most `capacity` waiting: past
// that they are refused (the caller counts them), never queued without end.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "bridge/common/time.hpp"

namespace dnbridge::daemon {

class Outbox {
 public:
  using Job = std::function<void()>;

  Outbox(std::string thread_name, std::size_t capacity);
  // Runs what is still waiting, then ends the thread.
  ~Outbox();
  Outbox(const Outbox&) = delete;
  Outbox& operator=(const Outbox&) = delete;

  // Queues `job` last; false (and not queued) when `capacity` jobs already
  // wait.
  bool post(Job job);

  // Until every job posted before the call has run, at most `timeout`.
  bool drain(Duration timeout);

  struct Counters {
    std::uint64_t run = 0;
    std::uint64_t refused = 0;  // refused for the capacity
    std::size_t waiting = 0;
  };
  Counters counters() const;

 private:
  struct Entry {
    Job job;
    std::uint64_t seq = 0;
  };
  void run();

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  std::deque<Entry> queue_;
  std::uint64_t next_seq_ = 1;
  std::uint64_t running_seq_ = 0;  // of the job running; 0 when none
  bool stopping_ = false;
  Counters counters_;
  std::thread thread_;
};

}  // namespace dnbridge::daemon
