// The job store in this process and its workers (jobs.h).
#include "http/jobs.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include "http/request_state.h"

namespace effectd {

using Clock = std::chrono::steady_clock;

const char* toString(JobState state) {
  switch (state) {
    case JobState::kQueued: return "queued";
    case JobState::kRunning: return "running";
    case JobState::kDone: return "done";
    case JobState::kFailed: return "failed";
    case JobState::kCancelled: return "cancelled";
  }
  return "unknown";
}

namespace {
unsigned jobIdCheck(const std::string& head) {  // FNV-1a, folded to 16 bits
  uint32_t h = 2166136261u;
  for (char c : "effectd-job:" + head) h = (h ^ uint8_t(c)) * 16777619u;
  return (h >> 16) ^ (h & 0xffffu);
}
}  // namespace

std::string newJobId() {
  char head[21];
  std::snprintf(head, sizeof head, "%08llx%.12s", static_cast<unsigned long long>(std::time(nullptr)) & 0xffffffffull,
                newRequestId().c_str());
  char id[25];
  std::snprintf(id, sizeof id, "%s%04x", head, jobIdCheck(head));
  return id;
}

std::optional<long long> jobIdTime(const std::string& id) {
  if (id.size() != 24 || id.find_first_not_of("0123456789abcdef") != std::string::npos) return std::nullopt;
  char check[5];
  std::snprintf(check, sizeof check, "%04x", jobIdCheck(id.substr(0, 20)));
  if (id.compare(20, 4, check) != 0) return std::nullopt;
  return std::stoll(id.substr(0, 8), nullptr, 16);
}

class LocalJobs final : public Jobs {
 public:
  LocalJobs(Options options, Runner runner);
  ~LocalJobs() override { stop(); }
  JobView submit(const std::string& effect, std::string body, const std::string& keyId, Refusal& refusal) override;
  std::optional<JobView> find(const std::string& id, bool withBody) override;
  std::optional<JobView> waitForChange(const std::string& id, uint64_t version, std::chrono::milliseconds timeout) override;
  std::optional<JobView> cancel(const std::string& id, std::chrono::milliseconds wait) override;
  bool remove(const std::string& id) override;
  void stop() override;
  std::string metricsText() const override;
  bool shared() const override { return false; }

 private:
  struct Job;
  void work();
  void expire();  // mu_ held: drops jobs past their ttl, and answers past maxStoreBytes
  JobView view(const Job& job) const;  // mu_ held
  void changed(Job& job);               // mu_ held: bumps the version, wakes waiters
  void dropRequest(Job& job);           // mu_ held: its body and the bytes it held, once it runs no more
  void forgetAnswer(const Job& job);    // mu_ held: the bytes its answer held, as the job goes

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

std::unique_ptr<Jobs> Jobs::inProcess(Options options, Runner runner) {
  return std::make_unique<LocalJobs>(options, std::move(runner));
}

struct LocalJobs::Job {
  std::string id, effect, keyId, body;
  JobState state = JobState::kQueued;
  double fraction = 0;
  size_t cells = 0, steps = 0;
  std::chrono::system_clock::time_point created = std::chrono::system_clock::now();
  Clock::time_point queuedAt = Clock::now(), startedAt, finishedAt;
  bool started = false;
  bool cancel = false;
  bool expired = false;
  uint64_t version = 0;
  std::shared_ptr<const JobAnswer> answer;
};

LocalJobs::LocalJobs(Options options, Runner runner) : o_(options), runner_(std::move(runner)) {
  for (int i = 0; i < o_.workers; ++i) workers_.emplace_back([this] { work(); });
}

void LocalJobs::stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
    for (auto& [id, job] : jobs_)
      if (!finished(job->state)) {
        job->cancel = true;
        changed(*job);
      }
  }
  queued_.notify_all();
  for (std::thread& t : workers_)
    if (t.joinable()) t.join();
  workers_.clear();
}

void LocalJobs::changed(Job& job) {
  ++job.version;
  change_.notify_all();
}

JobView LocalJobs::view(const Job& job) const {
  JobView v;
  v.id = job.id, v.effect = job.effect, v.keyId = job.keyId, v.state = job.state;
  v.fraction = job.fraction, v.cells = job.cells, v.steps = job.steps, v.created = job.created;
  const Clock::time_point now = Clock::now();
  const auto seconds = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
  const bool started = job.started;
  v.queuedS = seconds((started ? job.startedAt : finished(job.state) ? job.finishedAt : now) - job.queuedAt);
  if (started) v.runningS = seconds((finished(job.state) ? job.finishedAt : now) - job.startedAt);
  // The pace so far, once there is one: a DBM bolt's steps grow dearer as it grows, so this
  // is a lower bound that tightens towards the end.
  if (job.state == JobState::kRunning && job.fraction >= 0.02) v.etaS = v.runningS * (1 - job.fraction) / job.fraction;
  if (finished(job.state)) v.etaS = 0;
  v.cancelRequested = job.cancel, v.expired = job.expired, v.version = job.version, v.answer = job.answer;
  return v;
}

JobView LocalJobs::submit(const std::string& effect, std::string body, const std::string& keyId, Refusal& refusal) {
  std::lock_guard<std::mutex> lock(mu_);
  expire();
  refusal = Refusal::kNone;
  if (stopping_ || jobs_.size() >= o_.maxJobs || requestBytes_ + body.size() > o_.maxStoreBytes) {
    refusal = Refusal::kFull;
    return {};
  }
  if (!keyId.empty() && std::count_if(jobs_.begin(), jobs_.end(), [&](const auto& j) {
        return j.second->keyId == keyId && !finished(j.second->state);
      }) >= o_.perKey) {
    refusal = Refusal::kKeyBusy;
    return {};
  }
  auto job = std::make_shared<Job>();
  job->id = newJobId();
  job->effect = effect, job->keyId = keyId, job->body = std::move(body);
  requestBytes_ += job->body.size();
  jobs_[job->id] = job;
  queue_.push_back(job);
  queued_.notify_one();
  return view(*job);
}

std::optional<JobView> LocalJobs::find(const std::string& id, bool /*withBody*/) {
  std::lock_guard<std::mutex> lock(mu_);
  expire();
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  return view(*it->second);
}

std::optional<JobView> LocalJobs::waitForChange(const std::string& id, uint64_t version, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mu_);
  const Clock::time_point until = Clock::now() + timeout;
  for (;;) {
    auto it = jobs_.find(id);
    if (it == jobs_.end()) return std::nullopt;
    if (it->second->version != version || stopping_ || change_.wait_until(lock, until) == std::cv_status::timeout) {
      it = jobs_.find(id);
      if (it == jobs_.end()) return std::nullopt;
      return view(*it->second);
    }
  }
}

std::optional<JobView> LocalJobs::cancel(const std::string& id, std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mu_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return std::nullopt;
  std::shared_ptr<Job> job = it->second;
  if (job->state == JobState::kQueued) {
    queue_.erase(std::remove(queue_.begin(), queue_.end(), job), queue_.end());
    job->state = JobState::kCancelled;
    job->cancel = true;
    job->finishedAt = Clock::now();
    dropRequest(*job);
    ++outcomes_["cancelled"];
    changed(*job);
  } else if (job->state == JobState::kRunning) {
    job->cancel = true;
    changed(*job);
    change_.wait_for(lock, wait, [&] { return finished(job->state); });
  }
  return view(*job);
}

void LocalJobs::dropRequest(Job& job) {
  requestBytes_ -= job.body.size();
  job.body.clear();
  job.body.shrink_to_fit();
}

void LocalJobs::forgetAnswer(const Job& job) {
  if (job.answer) answerBytes_ -= job.answer->body.size();
}

bool LocalJobs::remove(const std::string& id) {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = jobs_.find(id);
  if (it == jobs_.end() || !finished(it->second->state)) return false;
  forgetAnswer(*it->second);
  jobs_.erase(it);
  change_.notify_all();
  return true;
}

void LocalJobs::expire() {
  const Clock::time_point now = Clock::now();
  for (auto it = jobs_.begin(); it != jobs_.end();) {
    const Job& job = *it->second;
    if (finished(job.state) && now - job.finishedAt > o_.ttl) {
      forgetAnswer(job);
      it = jobs_.erase(it);
      change_.notify_all();
    } else {
      ++it;
    }
  }
  while (answerBytes_ + requestBytes_ > o_.maxStoreBytes) {  // the oldest finished answer goes first
    Job* oldest = nullptr;
    for (auto& [id, job] : jobs_)
      if (finished(job->state) && job->answer && (!oldest || job->finishedAt < oldest->finishedAt)) oldest = job.get();
    if (!oldest) break;
    forgetAnswer(*oldest);
    oldest->answer.reset();
    oldest->expired = true;
    changed(*oldest);
  }
}

void LocalJobs::work() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock<std::mutex> lock(mu_);
      queued_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = queue_.front();
      queue_.pop_front();
      job->state = JobState::kRunning;
      job->started = true;
      job->startedAt = Clock::now();
      changed(*job);
    }
    const JobProgress progress = [this, job](double fraction, size_t cells, size_t steps) {
      std::lock_guard<std::mutex> lock(mu_);
      job->fraction = std::max(job->fraction, std::clamp(fraction, 0.0, 1.0));
      job->cells = cells, job->steps = steps;
      changed(*job);
      return !job->cancel;
    };
    JobAnswer answer;
    try {
      answer = runner_(job->effect, job->body, progress);
    } catch (const std::exception& e) {
      answer.status = 500;
      answer.headers["Content-Type"] = "application/problem+json";
      answer.body = std::string("{\"type\":\"https://effectd.dev/problems/internal\",\"title\":\"Internal Server "
                                "Error\",\"status\":500,\"detail\":\"the job failed\"}");
    }
    std::lock_guard<std::mutex> lock(mu_);
    job->state = job->cancel ? JobState::kCancelled : answer.status < 400 ? JobState::kDone : JobState::kFailed;
    if (job->state == JobState::kDone) job->fraction = 1;
    job->finishedAt = Clock::now();
    dropRequest(*job);
    if (job->state != JobState::kCancelled) {
      answerBytes_ += answer.body.size();
      job->answer = std::make_shared<const JobAnswer>(std::move(answer));
    }
    ++outcomes_[toString(job->state)];
    changed(*job);
    expire();
  }
}

std::string LocalJobs::metricsText() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::map<std::string, size_t> now;
  for (const char* s : {"queued", "running", "done", "failed", "cancelled"}) now[s] = 0;
  for (const auto& [id, job] : jobs_) ++now[toString(job->state)];
  std::string out = "# HELP effectd_jobs Jobs kept, by state.\n# TYPE effectd_jobs gauge\n";
  for (const auto& [state, n] : now) out += "effectd_jobs{state=\"" + state + "\"} " + std::to_string(n) + "\n";
  out += "# HELP effectd_jobs_finished_total Jobs finished, by how.\n# TYPE effectd_jobs_finished_total counter\n";
  for (const char* s : {"done", "failed", "cancelled"}) {
    auto it = outcomes_.find(s);
    out += std::string("effectd_jobs_finished_total{state=\"") + s + "\"} " +
           std::to_string(it == outcomes_.end() ? 0 : it->second) + "\n";
  }
  out += "# HELP effectd_job_store_bytes Bytes of queued jobs' requests and finished jobs' answers kept.\n"
         "# TYPE effectd_job_store_bytes gauge\neffectd_job_store_bytes " + std::to_string(answerBytes_ + requestBytes_) + "\n";
  return out;
}

}  // namespace effectd
