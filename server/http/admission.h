// Admission control: a global memory budget and a bound on heavy computations.
//
// Every request states, before it starts, the peak bytes it will need (its estimate) and
// whether it is heavy (seconds of CPU: the Laplace solvers, huge grids, meshes and renders).
// It is admitted when its bytes fit in what the budget has left and, if heavy, when a heavy
// slot is free; otherwise it waits in a bounded queue for a bounded time, first come first
// served within its class, and is then refused with 503 + Retry-After. Light and heavy
// requests queue apart: a small request never waits behind bolts waiting for a heavy slot. A request larger than the
// whole budget can never run: 413 naming --memory-budget-mb. The ticket releases its bytes and slot when destroyed —
// after the answer has been written, since the answer's bytes count too.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>

namespace effectd {

class Admission {
 public:
  struct Options {
    size_t budgetBytes = 0;
    int heavySlots = 1;
    int maxWaiting = 64;
    std::chrono::milliseconds maxWait{10000};
  };
  explicit Admission(Options options) : o_(options) {}

  class Ticket {
   public:
    Ticket() = default;
    Ticket(Ticket&& other) noexcept { *this = std::move(other); }
    Ticket& operator=(Ticket&& other) noexcept;
    ~Ticket() { release(); }
    void release();
    size_t bytes() const { return bytes_; }

   private:
    friend class Admission;
    Admission* owner_ = nullptr;
    size_t bytes_ = 0;
    bool heavy_ = false;
  };

  // Waits until admitted; throws ApiError 413 (larger than the budget) or 503 (queue full,
  // or not admitted within maxWait).
  Ticket admit(size_t bytes, bool heavy);

  struct Counts {
    size_t budgetBytes = 0, reservedBytes = 0, peakReservedBytes = 0;
    int heavyRunning = 0, waiting = 0, maxWaiting = 0;
    uint64_t admitted = 0, waited = 0, refusedBusy = 0, refusedTooLarge = 0;
  };
  Counts counts() const;
  bool queueFull() const;

 private:
  bool fits(size_t bytes, bool heavy) const;  // mu_ held
  void release(size_t bytes, bool heavy);

  const Options o_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<uint64_t> queue_[2];  // waiting requests in arrival order: [0] light, [1] heavy
  uint64_t nextId_ = 0;
  Counts c_;
};

// The default budget: a fraction of the cgroup's memory limit (v2 memory.max, v1
// memory.limit_in_bytes) when there is one, else of physical memory.
struct MemoryLimit {
  size_t bytes = 0;
  std::string source;  // "cgroup v2 memory.max", "cgroup v1 memory.limit_in_bytes", "physical memory"
};
MemoryLimit detectMemoryLimit();
constexpr double kDefaultBudgetFraction = 0.6;

}  // namespace effectd
