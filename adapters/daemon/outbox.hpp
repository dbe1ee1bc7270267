#pragma once
// Writes to DDS on a thread of its own, so that no write ever runs on a
// thread that drives a bus. A reliable write can wait (a reader that does not
// acknowledge fills the writer's history, and Cyclone then blocks the write
// for up to the reliability max_blocking_time); here only this thread waits,
// and the port loops go on polling.
//
// Jobs run in the order they were posted. A job posted with a key replaces
// the one of the same key still waiting, in its place: a state topic keeps
// one sample per instance, and a thread that fell behind writes the newest
// only. Jobs posted without a key are bounded in number: past the capacity
// they are refused (the caller counts them), never queued without end.
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>

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

  // Replaces the waiting job of `key`, or queues `job` last.
  void post(std::string key, Job job);
  // Queues `job` last; false (and not queued) when `capacity` unkeyed jobs
  // already wait.
  bool post(Job job);
  // Queues `job` last whatever the capacity (what must not be lost, such as
  // an unregistration, and is bounded by its caller).
  void post_always(Job job);
  // The same, and the jobs of `keys` still waiting can no longer be
  // replaced: they run before `job`, and one posted later with such a key
  // queues after it (a node's instances disposed after its last sample, and
  // before the first sample of a node added later under the same key).
  void post_always_after(std::span<const std::string> keys, Job job);

  // Until every job posted before the call has run, at most `timeout`.
  bool drain(Duration timeout);

  struct Counters {
    std::uint64_t run = 0;
    std::uint64_t replaced = 0;  // keyed jobs replaced before they ran
    std::uint64_t refused = 0;   // unkeyed jobs refused for the capacity
    std::size_t waiting = 0;
  };
  Counters counters() const;

 private:
  struct Entry {
    std::string key;  // empty: unkeyed
    Job job;
    std::uint64_t seq = 0;  // when first queued; a replacement keeps it
  };
  void run();
  void push(Entry entry);  // with mutex_ held

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  std::list<Entry> queue_;
  std::unordered_map<std::string, std::list<Entry>::iterator> by_key_;
  std::size_t unkeyed_ = 0;
  std::uint64_t next_seq_ = 1;
  std::uint64_t running_seq_ = 0;  // of the job running; 0 when none
  bool stopping_ = false;
  Counters counters_;
  std::thread thread_;
};

}  // namespace dnbridge::daemon
