// Freed memory: kept in the process while requests come, handed back once it goes idle.
//
// glibc gives a freed block back to the kernel at once when it was mmap'd (above its mmap
// threshold) or when an arena's free top passes the trim threshold, and the next request
// faults the same pages in again. A fault costs ~0.2 us on bare metal but ~13 us in a
// Firecracker microVM with shadow paging, where a 128^2 bolt spent two thirds of its time
// faulting in pages the previous bolt had just returned (docs/architecture.md, "Memory
// between requests").
// So blocks up to 32 MB come from the heap and stay there between requests, and a background
// thread trims the heap once no request has held memory for a second: a burst's peak goes
// back to the system, a steady stream of requests keeps its pages.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace effectd {

class IdleTrim {
 public:
  // The allocator settings above; once, at startup, before any thread allocates.
  static void configureAllocator();

  // `idle` says whether no request holds memory now.
  explicit IdleTrim(std::function<bool()> idle, std::chrono::milliseconds after = std::chrono::seconds(1));
  ~IdleTrim();
  IdleTrim(const IdleTrim&) = delete;
  IdleTrim& operator=(const IdleTrim&) = delete;

  // A request finished: memory may be waiting to go back.
  void noteFinished();
  // Trims done so far (for tests and metrics).
  uint64_t trims() const;

 private:
  void loop();

  const std::function<bool()> idle_;
  const std::chrono::milliseconds after_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false, pending_ = false;
  std::chrono::steady_clock::time_point last_{};
  uint64_t trims_ = 0;
  std::thread thread_;
};

}  // namespace effectd
