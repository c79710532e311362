// effects/parallel.h — how the library uses several cores: only when the caller says so.
//
// The library never starts threads of its own (meshoptimizer's rule). An algorithm that can
// split its work takes a `Parallel*` in its options; null means the calling thread does all
// of it. A server makes one `ThreadPool` at start-up and hands it to every request, so no
// request pays for creating threads and the process never runs more compute threads than it
// chose. Results never depend on the split: every index is computed by exactly one chunk.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "effects/export.h"

EFFECTS_API_BEGIN
namespace effects {

class Parallel {
 public:
  virtual ~Parallel() = default;
  // Calls fn(begin, end) for disjoint chunks that cover [0, n), each at least `grain` long
  // (except when n < grain), possibly several at once; returns when all have returned.
  virtual void forRange(size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn) = 0;
};

// forRange on `parallel`, or on the calling thread when it is null.
void forRange(Parallel* parallel, size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn);

// `threads` workers that run chunks beside the calling thread. Safe to call from many threads
// at once: each call's chunks are shared by its caller and whichever workers are free, and the
// caller always makes progress on its own call (no deadlock when every worker is busy).
class ThreadPool final : public Parallel {
 public:
  explicit ThreadPool(size_t threads);
  ~ThreadPool() override;
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  void forRange(size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn) override;
  size_t threads() const { return workers_.size(); }
  // Workers for the rest of the machine: its cores less the calling thread (at least 0).
  static size_t besideCaller();

 private:
  struct Call;
  void work();
  static void runChunks(Call& call);
  std::mutex mu_;
  std::condition_variable wake_, left_;
  std::vector<Call*> active_;
  std::vector<std::thread> workers_;
  bool stopping_ = false;
};

}  // namespace effects
EFFECTS_API_END
