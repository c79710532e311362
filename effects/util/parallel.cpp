#include "effects/parallel.h"

#include <algorithm>
#include <atomic>

#include "check.h"

namespace effects {

void forRange(Parallel* parallel, size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn) {
  if (parallel) return parallel->forRange(n, grain, fn);
  if (n) fn(0, n);
}

struct ThreadPool::Call {
  const std::function<void(size_t, size_t)>* fn = nullptr;
  size_t n = 0, chunk = 0, chunks = 0;
  std::atomic<size_t> next{0};
  size_t helpers = 0;  // workers inside runChunks for this call (guarded by mu_)
};

size_t ThreadPool::besideCaller() { return std::max(1u, std::thread::hardware_concurrency()) - 1; }

ThreadPool::ThreadPool(size_t threads) {
  for (size_t i = 0; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::runChunks(Call& call) {
  for (size_t k; (k = call.next.fetch_add(1)) < call.chunks;)
    (*call.fn)(k * call.chunk, std::min(call.n, (k + 1) * call.chunk));
}

void ThreadPool::forRange(size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn) {
  grain = std::max<size_t>(grain, 1);
  // Up to four chunks per thread, taken in turn: a thread that was descheduled, or drew the
  // slower part of the range, holds up the call by one small chunk, not by half the work.
  const size_t chunks = workers_.empty() ? 1 : std::min(4 * (workers_.size() + 1), n / grain);
  if (chunks < 2) {
    if (n) fn(0, n);
    return;
  }
  Call call;
  call.fn = &fn;
  call.n = n;
  call.chunk = (n + chunks - 1) / chunks;
  call.chunks = (n + call.chunk - 1) / call.chunk;
  {
    std::lock_guard<std::mutex> lock(mu_);
    active_.push_back(&call);
  }
  wake_.notify_all();
  runChunks(call);
  std::unique_lock<std::mutex> lock(mu_);
  active_.erase(std::find(active_.begin(), active_.end(), &call));  // no new helpers
  left_.wait(lock, [&] { return call.helpers == 0; });              // running chunks finish
}

void ThreadPool::work() {
  std::unique_lock<std::mutex> lock(mu_);
  for (;;) {
    Call* call = nullptr;
    wake_.wait(lock, [&] {
      if (stopping_) return true;
      for (Call* c : active_)
        if (c->next.load() < c->chunks) return (call = c), true;
      return false;
    });
    if (!call) return;  // stopping
    ++call->helpers;
    lock.unlock();
    runChunks(*call);
    lock.lock();
    CHECK_GT(call->helpers, size_t(0));
    if (--call->helpers == 0) left_.notify_all();
  }
}

}  // namespace effects
