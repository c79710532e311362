// The HTTP connection pool. cpp-httplib serves a connection on one thread from start to end,
// and its read timeout is per read: a client trickling one header byte at a time holds a thread for as
// long as it likes. A fixed pool lets a handful of such clients starve everyone else, so the
// pool keeps `base` threads and grows, one thread per connection, up to `max`; only beyond
// that do connections wait. (A proxy that buffers whole requests, as deploy/nginx does, is
// the defence against attackers with more than `max` connections.)
#pragma once

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <httplib.h>

namespace effectd {

class ElasticPool : public httplib::TaskQueue {
 public:
  ElasticPool(size_t base, size_t max) : base_(base), max_(std::max(base, max)) {
    for (size_t i = 0; i < base_; ++i) spawn();
  }
  ~ElasticPool() override { shutdown(); }
  void enqueue(std::function<void()> fn) override {
    std::unique_lock<std::mutex> lock(mu_);
    jobs_.push_back(std::move(fn));
    // Idle threads may not have woken for earlier jobs yet: count jobs, not wake-ups.
    if (jobs_.size() > idle_ && threads_.size() < max_) spawn();
    cv_.notify_one();
  }
  void shutdown() override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (stopping_) return;
      stopping_ = true;
    }
    cv_.notify_all();
    for (auto& t : threads_) t.join();
  }

 private:
  void spawn() {  // with mu_ held, or from the constructor
    threads_.emplace_back([this] { work(); });
  }
  void work() {
    std::unique_lock<std::mutex> lock(mu_);
    for (;;) {
      ++idle_;
      cv_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
      --idle_;
      if (jobs_.empty()) return;  // stopping and drained
      auto job = std::move(jobs_.front());
      jobs_.pop_front();
      lock.unlock();
      job();
      lock.lock();
    }
  }
  const size_t base_, max_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  size_t idle_ = 0;
  bool stopping_ = false;
};

}  // namespace effectd
