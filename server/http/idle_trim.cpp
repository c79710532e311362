#include "http/idle_trim.h"

#include <malloc.h>

namespace effectd {

void IdleTrim::configureAllocator() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest: bigger blocks are mmap'd all the same
  mallopt(M_TRIM_THRESHOLD, 1 << 30);   // freeing never trims; IdleTrim does
  // One arena: malloc_trim shrinks only the main arena's top, so a thread arena's heap (up to
  // 64 MB each) would keep its free top for good (a burst left 492 MB where it started at
  // 208; with one arena 262 MB). Small blocks come from per-thread caches all the same.
  mallopt(M_ARENA_MAX, 1);
}

IdleTrim::IdleTrim(std::function<bool()> idle, std::chrono::milliseconds after)
    : idle_(std::move(idle)), after_(after), thread_([this] { loop(); }) {}

IdleTrim::~IdleTrim() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void IdleTrim::noteFinished() {
  std::lock_guard<std::mutex> lock(mu_);
  pending_ = true;
  last_ = std::chrono::steady_clock::now();
}

uint64_t IdleTrim::trims() const {
  std::lock_guard<std::mutex> lock(mu_);
  return trims_;
}

void IdleTrim::loop() {
  std::unique_lock<std::mutex> lock(mu_);
  while (!stop_) {
    cv_.wait_for(lock, after_ / 4);
    if (stop_ || !pending_ || std::chrono::steady_clock::now() - last_ < after_) continue;
    if (!idle_()) continue;  // a request still running will note its end
    pending_ = false;
    lock.unlock();
    malloc_trim(0);  // the heap's free top and the free pages inside it
    lock.lock();
    ++trims_;
  }
}

}  // namespace effectd
