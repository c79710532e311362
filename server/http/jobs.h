// Long work as jobs (docs/api.md, "Jobs"): a request queued, run by a few worker threads under
// the job limits, its progress kept for polling and Server-Sent Events, its answer kept for a
// while. This file knows nothing of HTTP: the service (jobs_api.cpp) hands it a runner that
// answers a body as the effect's endpoint does, and serves what it keeps.
//
// Two stores behind one interface (docs/serving.md, "Jobs"):
//   - in this process (Jobs::inProcess, jobs.cpp): a restart loses the queue, the running work
//     and the answers;
//   - in Redis (Jobs::inRedis, jobs_redis.cpp, --jobs-redis): every replica that shares it
//     answers any job's state and result, and idle replicas take queued work; a replica that
//     stops hands its running jobs back to the queue, and one that dies is found by its lease
//     running out, its job queued again (failed after kMaxAttempts).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace effectd {

enum class JobState { kQueued, kRunning, kDone, kFailed, kCancelled };
const char* toString(JobState state);
inline bool finished(JobState s) { return s == JobState::kDone || s == JobState::kFailed || s == JobState::kCancelled; }

// Job ids: 8 hex digits of the Unix time the job was made, 12 random ones, and 4 of a check
// over both. So an id this service made is told from one it never made, and its age is known:
// a store that no longer holds a job answers 410 with why, an id never made 404.
std::string newJobId();
// The Unix time an id from newJobId() was made at; nullopt for an id it did not make.
std::optional<long long> jobIdTime(const std::string& id);

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
  std::string worker;                // running (or ran) on: "host:pid" (a shared store's replica)
  uint64_t version = 0;              // grows with every change (Server-Sent Events wait on it)
  std::shared_ptr<const JobAnswer> answer;  // done, failed, or cancelled while running
};

// What the store could not do: Redis unreachable (the service answers 503).
struct JobStoreError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Jobs {
 public:
  struct Options {
    int workers = 1;
    size_t maxJobs = 256;           // kept at once, in any state
    std::chrono::seconds ttl{3600};  // a finished job is forgotten this long after it finished
    // Queued requests and kept answers at once: past it the oldest answers are dropped, and a
    // job whose request would not fit is refused (in this process; Redis keeps what its
    // maxmemory allows).
    size_t maxStoreBytes = 256u << 20;
    int perKey = 2;                 // an API key's jobs queued or running at once
  };
  // Answers `body` as the endpoint of `effect` does, reporting progress through `progress`.
  using Runner = std::function<JobAnswer(const std::string& effect, const std::string& body, const JobProgress& progress)>;

  static std::unique_ptr<Jobs> inProcess(Options options, Runner runner);
  // `redisUrl`: redis://host:port. Throws JobStoreError when Redis cannot be reached at start.
  static std::unique_ptr<Jobs> inRedis(Options options, Runner runner, const std::string& redisUrl);
  virtual ~Jobs() = default;

  enum class Refusal { kNone, kFull, kKeyBusy };
  // Queues a job; on refusal, `refusal` says why and the view is empty.
  virtual JobView submit(const std::string& effect, std::string body, const std::string& keyId, Refusal& refusal) = 0;
  // The job (its answer's bytes only with `withBody`: a poll needs its status and headers).
  virtual std::optional<JobView> find(const std::string& id, bool withBody = false) = 0;
  // Waits until the job changes past `version`, or `timeout`; its view then (nullopt: gone).
  virtual std::optional<JobView> waitForChange(const std::string& id, uint64_t version,
                                               std::chrono::milliseconds timeout) = 0;
  // Cancels a queued job at once, or asks a running one to stop and waits up to `wait` for it.
  virtual std::optional<JobView> cancel(const std::string& id, std::chrono::milliseconds wait) = 0;
  // Forgets a finished job and its answer; false when there is none or it is not finished.
  virtual bool remove(const std::string& id) = 0;
  // Stops the workers: in this process every job is cancelled; in Redis the running ones go
  // back to the queue for another replica.
  virtual void stop() = 0;
  virtual std::string metricsText() const = 0;
  virtual bool shared() const = 0;
  // The shared store's state for /readyz ("" = answering; in this process, always), and its
  // failed exchanges for /metrics.
  virtual std::string storeProblem() { return ""; }
  virtual uint64_t storeFailures() const { return 0; }
  // Whether the store came back so lately that the replicas may not yet have registered their
  // running jobs again (a job not found then is not known to be gone).
  virtual bool settling() { return false; }
};

}  // namespace effectd
