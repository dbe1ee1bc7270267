#include "adapters/daemon/outbox.hpp"

#include "adapters/port/thread_name.hpp"

namespace dnbridge::daemon {

Outbox::Outbox(std::string thread_name, std::size_t capacity) : capacity_(capacity) {
  thread_ = std::thread([this] { run(); });
  port::name_thread(thread_, thread_name);
}

Outbox::~Outbox() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void Outbox::push(Entry entry) {
  entry.seq = next_seq_++;
  if (entry.key.empty()) ++unkeyed_;
  queue_.push_back(std::move(entry));
  if (!queue_.back().key.empty()) by_key_.emplace(queue_.back().key, std::prev(queue_.end()));
}

void Outbox::post(std::string key, Job job) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = by_key_.find(key); it != by_key_.end()) {
      it->second->job = std::move(job);
      ++counters_.replaced;
      return;
    }
    push(Entry{std::move(key), std::move(job)});
  }
  wake_.notify_one();
}

bool Outbox::post(Job job) {
  {
    std::lock_guard lock(mutex_);
    if (unkeyed_ >= capacity_) {
      ++counters_.refused;
      return false;
    }
    push(Entry{{}, std::move(job)});
  }
  wake_.notify_one();
  return true;
}

void Outbox::post_always(Job job) {
  {
    std::lock_guard lock(mutex_);
    push(Entry{{}, std::move(job)});
  }
  wake_.notify_one();
}

void Outbox::post_always_after(std::span<const std::string> keys, Job job) {
  {
    std::lock_guard lock(mutex_);
    for (const auto& key : keys) by_key_.erase(key);
    push(Entry{{}, std::move(job)});
  }
  wake_.notify_one();
}

bool Outbox::drain(Duration timeout) {
  std::unique_lock lock(mutex_);
  const std::uint64_t last = next_seq_ - 1;
  return done_.wait_for(lock, timeout, [&] {
    return (queue_.empty() || queue_.front().seq > last) &&
           (running_seq_ == 0 || running_seq_ > last);
  });
}

Outbox::Counters Outbox::counters() const {
  std::lock_guard lock(mutex_);
  Counters c = counters_;
  c.waiting = queue_.size();
  return c;
}

void Outbox::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and nothing left
    if (queue_.front().key.empty()) {
      --unkeyed_;
    } else if (auto it = by_key_.find(queue_.front().key);
               it != by_key_.end() && it->second == queue_.begin()) {
      // (A job no longer replaceable has no entry, or another job's.)
      by_key_.erase(it);
    }
    Entry entry = std::move(queue_.front());
    queue_.pop_front();
    running_seq_ = entry.seq;
    lock.unlock();
    entry.job();
    entry.job = nullptr;  // what it holds goes before the lock is taken again
    lock.lock();
    running_seq_ = 0;
    ++counters_.run;
    done_.notify_all();
  }
}

}  // namespace dnbridge::daemon
