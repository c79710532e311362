// Long work as jobs (docs/api.md, "Jobs"): a request queued, run by a few worker threads under
// the job limits, its progress kept for polling and Server-Sent Events, its answer kept for a
// while. This file knows nothing of HTTP: the service (jobs_api.cpp) hands it a runner that
// answers a body as the effect's endpoint does, and serves what it keeps.
//
// Jobs live in this process: a restart loses the queue, the running work and the answers
// (docs/serving.md, "Jobs").
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace effectd {

enum class JobState { kQueued, kRunning, kDone, kFailed, kCancelled };
const char* toString(JobState state);
inline bool finished(JobState s) { return s == JobState::kDone || s == JobState::kFailed || s == JobState::kCancelled; }

// What a job's run answered: the endpoint's status, headers and bytes (a problem when it failed).
struct JobAnswer {
  int status = 0;
  std::map<std::string, std::string> headers;
  std::string body;
};

// Reports how far the work has come (fraction in [0, 1], the bolt's cells and steps); false
// when the job is cancelled and the work should stop.
using JobProgress = std::function<bool(double fraction, size_t cells, size_t steps)>;

// A copy of a job, read outside the store's lock.
struct JobView {
  std::string id, effect, keyId;
  JobState state = JobState::kQueued;
  double fraction = 0;
  size_t cells = 0, steps = 0;
  std::chrono::system_clock::time_point created;
  double queuedS = 0, runningS = 0;  // seconds spent in each so far
  double etaS = -1;                  // seconds left, from the fraction's pace; -1: not known yet
  bool cancelRequested = false;
  bool expired = false;              // finished, its answer dropped for room (Options::maxStoreBytes)
  uint64_t version = 0;              // grows with every change (Server-Sent Events wait on it)
  std::shared_ptr<const JobAnswer> answer;  // done, failed, or cancelled while running
};

class Jobs {
 public:
  struct Options {
    int workers = 1;
    size_t maxJobs = 256;           // kept at once, in any state
    std::chrono::seconds ttl{3600};  // a finished job is forgotten this long after it finished
    // Queued requests and kept answers at once: past it the oldest answers are dropped, and a
    // job whose request would not fit is refused.
    size_t maxStoreBytes = 256u << 20;
    int perKey = 2;                 // an API key's jobs queued or running at once
  };
  // Answers `body` as the endpoint of `effect` does, reporting progress through `progress`.
  using Runner = std::function<JobAnswer(const std::string& effect, const std::string& body, const JobProgress& progress)>;

  Jobs(Options options, Runner runner);
  ~Jobs();  // stop()
  Jobs(const Jobs&) = delete;
  Jobs& operator=(const Jobs&) = delete;

  enum class Refusal { kNone, kFull, kKeyBusy };
  // Queues a job; on refusal, `refusal` says why and the view is empty.
  JobView submit(const std::string& effect, std::string body, const std::string& keyId, Refusal& refusal);
  std::optional<JobView> find(const std::string& id);
  // Waits until the job changes past `version`, or `timeout`; its view then (nullopt: gone).
  std::optional<JobView> waitForChange(const std::string& id, uint64_t version, std::chrono::milliseconds timeout);
  // Cancels a queued job at once, or asks a running one to stop and waits up to `wait` for it.
  std::optional<JobView> cancel(const std::string& id, std::chrono::milliseconds wait);
  // Forgets a finished job and its answer; false when there is none or it is not finished.
  bool remove(const std::string& id);
  // Cancels every job and joins the workers (the process is stopping).
  void stop();

  std::string metricsText() const;

 private:
  struct Job;
  void work();
  void expire();  // mu_ held: drops jobs past their ttl, and answers past maxStoreBytes
  JobView view(const Job& job) const;  // mu_ held
  void changed(Job& job);               // mu_ held: bumps the version, wakes waiters

  const Options o_;
  const Runner runner_;
  mutable std::mutex mu_;
  std::condition_variable queued_, change_;
  std::map<std::string, std::shared_ptr<Job>> jobs_;
  std::deque<std::shared_ptr<Job>> queue_;
  size_t answerBytes_ = 0, requestBytes_ = 0;  // kept answers, queued requests
  bool stopping_ = false;
  std::map<std::string, uint64_t> outcomes_;  // finished jobs by state, for /metrics
  std::vector<std::thread> workers_;
};

}  // namespace effectd
