// A fixed set of render threads, one EGL context each, fed by a bounded queue.
#include "render/render.h"

namespace effects::render {

RenderPool::RenderPool(PoolOptions options) : options_(std::move(options)) {
  options_.threads = std::max(1, options_.threads);
  options_.queue = std::max(0, options_.queue);
}

RenderPool::~RenderPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

std::string RenderPool::start() {
  std::unique_lock<std::mutex> lock(mu_);
  if (workers_.empty())
    for (int i = 0; i < options_.threads; ++i) workers_.emplace_back([this, i] { worker(i); });
  ready_.wait(lock, [&] { return started_ == options_.threads; });
  return startError_;
}

std::string RenderPool::description() {
  std::lock_guard<std::mutex> lock(mu_);
  return description_;
}

std::optional<std::future<Result<Frame>>> RenderPool::submit(Scene scene) {
  return submit(std::move(scene), Sequence{0, {}, {}});
}

std::optional<std::future<Result<Frame>>> RenderPool::submit(Scene scene, Sequence sequence) {
  if (!start().empty()) {
    std::promise<Result<Frame>> failed;
    failed.set_value(unsatisfiable("/renderer", startError_));
    return failed.get_future();
  }
  std::lock_guard<std::mutex> lock(mu_);
  // Jobs beyond the idle workers wait; at most `queue` of them.
  const int idle = options_.threads - busy_.load();
  if (int(jobs_.size()) >= options_.queue + std::max(0, idle)) return std::nullopt;
  jobs_.push_back(Job{std::move(scene), std::nullopt, {}, {}});
  if (sequence.count > 0) jobs_.back().sequence = std::move(sequence);
  auto future = jobs_.back().done.get_future();
  wake_.notify_one();
  return future;
}

void RenderPool::worker(int) {
  auto renderer = Renderer::create(options_.platform);
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!renderer.ok() && startError_.empty()) startError_ = renderer.error().message;
    if (renderer.ok() && description_.empty()) description_ = renderer.value()->description();
    ++started_;
  }
  ready_.notify_all();
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
      if (jobs_.empty()) return;  // stopping, nothing left
      job = std::move(jobs_.front());
      jobs_.pop_front();
      int now = ++busy_;
      int peak = peakBusy_.load();
      while (now > peak && !peakBusy_.compare_exchange_weak(peak, now)) {
      }
    }
    try {
      const double queueMs = job.queued.ms();
      Result<Frame> frame = !renderer.ok()   ? Result<Frame>(unsatisfiable("/renderer", renderer.error().message))
                            : job.sequence ? renderer.value()->render(job.scene, *job.sequence)
                                           : renderer.value()->render(job.scene);
      if (frame.ok()) frame.value().queueMs = queueMs;
      job.done.set_value(std::move(frame));
    } catch (const std::exception& e) {
      job.done.set_value(unsatisfiable("/renderer", std::string("render failed: ") + e.what()));
    }
    --busy_;
  }
}

}  // namespace effects::render
