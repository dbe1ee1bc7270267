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

bool Outbox::post(Job job) {
  {
    std::lock_guard lock(mutex_);
    if (queue_.size() >= capacity_) {
      ++counters_.refused;
      return false;
    }
    queue_.push_back(Entry{std::move(job), next_seq_++});
  }
  wake_.notify_one();
  return true;
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
