// The job store in Redis (jobs.h, --jobs-redis): shared by every replica that names the same
// Redis. Each change is one Lua script, atomic there, timed by Redis's own clock (replicas'
// clocks may differ):
//   effectd:jobs:job:<id>   hash: effect, key, state, body (while queued or running), created,
//                           queued, started, finished (ms), fraction, cells, steps, worker,
//                           lease (ms), cancel, attempts, version, and once finished a_status,
//                           a_headers (JSON), a_body; it expires --job-ttl after it finished
//   effectd:jobs:queue      list of queued ids, oldest first
//   effectd:jobs:running    set of running ids (what the reaper looks at)
//   effectd:jobs:all        sorted set of kept ids by when they expire (--max-jobs counts it)
//   effectd:jobs:key:<key>  set of an API key's queued and running ids (--key-max-jobs)
//   effectd:jobs:finished:<state>  counters for /metrics
// A worker holds a lease on its job, renewed every kHeartbeat; every replica's heartbeat also
// reaps: a running job whose lease ran out (its replica died) is queued again, and failed after
// kMaxAttempts. A replica that stops puts its running jobs back at the head of the queue.
// A Redis that comes back without its data (restarted empty, or its keys evicted) has lost the
// jobs: each replica's heartbeat registers the ones it runs again, with their progress, and an
// answer that could not be stored is stored when Redis answers again (docs/serving.md, "Jobs").
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "http/jobs.h"
#include "http/redis.h"
#include "http/request_state.h"

namespace effectd {

namespace {

constexpr auto kLease = std::chrono::seconds(10);
constexpr auto kHeartbeat = std::chrono::seconds(2);
constexpr auto kIdlePoll = std::chrono::milliseconds(200);  // a worker with nothing to do looks again
constexpr auto kWatchPoll = std::chrono::milliseconds(100);  // a change waited for
constexpr int kMaxAttempts = 3;

// Shared by every script: Redis's clock in ms, and a job's end.
constexpr const char* kPrelude = R"(
local function now() local t = redis.call('TIME') return tonumber(t[1]) * 1000 + math.floor(tonumber(t[2]) / 1000) end
local function jobKey(id) return 'effectd:jobs:job:' .. id end
local function finish(id, state, status, headers, body, t, ttl)
  local h = jobKey(id)
  local key = redis.call('HGET', h, 'key')
  redis.call('HSET', h, 'state', state, 'finished', t)
  if state == 'done' then redis.call('HSET', h, 'fraction', '1') end
  if status ~= '' then redis.call('HSET', h, 'a_status', status, 'a_headers', headers, 'a_body', body) end
  redis.call('HDEL', h, 'body', 'lease')
  redis.call('HINCRBY', h, 'version', 1)
  redis.call('SREM', 'effectd:jobs:running', id)
  if key and key ~= '' then redis.call('SREM', 'effectd:jobs:key:' .. key, id) end
  redis.call('ZADD', 'effectd:jobs:all', t + ttl, id)
  redis.call('PEXPIRE', h, ttl)
  redis.call('INCR', 'effectd:jobs:finished:' .. state)
end
)";

// ARGV: id, effect, key, body, maxJobs, perKey -> 'ok', 'full' or 'busy'
constexpr const char* kSubmit = R"(
local t = now()
redis.call('ZREMRANGEBYSCORE', 'effectd:jobs:all', '-inf', t)
if redis.call('ZCARD', 'effectd:jobs:all') >= tonumber(ARGV[5]) then return 'full' end
if ARGV[3] ~= '' and redis.call('SCARD', 'effectd:jobs:key:' .. ARGV[3]) >= tonumber(ARGV[6]) then return 'busy' end
redis.call('HSET', jobKey(ARGV[1]), 'effect', ARGV[2], 'key', ARGV[3], 'state', 'queued', 'body', ARGV[4], 'created', t,
           'queued', t, 'version', 1, 'fraction', '0', 'cells', 0, 'steps', 0, 'attempts', 0)
redis.call('ZADD', 'effectd:jobs:all', 9e15, ARGV[1])
if ARGV[3] ~= '' then redis.call('SADD', 'effectd:jobs:key:' .. ARGV[3], ARGV[1]) end
redis.call('RPUSH', 'effectd:jobs:queue', ARGV[1])
return 'ok'
)";

// ARGV: id, withBody -> nil, or {fields, now, a_body or nil}
constexpr const char* kView = R"(
local h = jobKey(ARGV[1])
if redis.call('EXISTS', h) == 0 then return false end
local f = redis.call('HMGET', h, 'effect', 'key', 'state', 'fraction', 'cells', 'steps', 'created', 'queued', 'started',
                     'finished', 'cancel', 'version', 'worker', 'a_status', 'a_headers')
local body = false
if ARGV[2] == '1' or f[3] == 'failed' then body = redis.call('HGET', h, 'a_body') end
return {f, now(), body}
)";

// ARGV: worker, leaseMs -> nil, or {id, effect, body, key, created}
constexpr const char* kClaim = R"(
while true do
  local id = redis.call('LPOP', 'effectd:jobs:queue')
  if not id then return false end
  local h = jobKey(id)
  if redis.call('HGET', h, 'state') == 'queued' then
    local t = now()
    redis.call('HSET', h, 'state', 'running', 'worker', ARGV[1], 'lease', t + tonumber(ARGV[2]), 'started', t)
    redis.call('HINCRBY', h, 'version', 1)
    redis.call('SADD', 'effectd:jobs:running', id)
    local v = redis.call('HMGET', h, 'effect', 'body', 'key', 'created')
    return {id, v[1], v[2], v[3] or '', v[4] or tostring(t)}
  end
end
)";

// ARGV: id, worker, fraction, cells, steps, then kRegister's from its sixth -> 1 go on (2: and
// Redis had lost it: made again first), 0 stop (cancelled, or no longer this worker's).
constexpr const char* kProgress = R"(
local again = register(6)
local h = jobKey(ARGV[1])
local v = redis.call('HMGET', h, 'state', 'worker', 'fraction', 'cancel')
if v[1] ~= 'running' or v[2] ~= ARGV[2] then return 0 end
redis.call('HSET', h, 'fraction', tostring(math.max(tonumber(v[3]) or 0, tonumber(ARGV[3]))), 'cells', ARGV[4],
           'steps', ARGV[5])
redis.call('HINCRBY', h, 'version', 1)
if v[4] == '1' then return 0 end
return 1 + again
)";

// A running job this worker holds that Redis no longer has, made again as it was.
// ARGV (from `at`): id, worker, effect, key, created, fraction, cells, steps, leaseMs.
constexpr const char* kRegisterFn = R"(
local function register(at)
  local id = ARGV[at]
  local h = jobKey(id)
  if redis.call('EXISTS', h) == 1 then return 0 end
  local t = now()
  redis.call('HSET', h, 'effect', ARGV[at + 2], 'key', ARGV[at + 3], 'state', 'running', 'created', ARGV[at + 4],
             'queued', ARGV[at + 4], 'started', t, 'worker', ARGV[at + 1], 'lease', t + tonumber(ARGV[at + 8]),
             'fraction', ARGV[at + 5], 'cells', ARGV[at + 6], 'steps', ARGV[at + 7], 'version', 1, 'attempts', 0)
  redis.call('ZADD', 'effectd:jobs:all', 9e15, id)
  redis.call('SADD', 'effectd:jobs:running', id)
  if ARGV[at + 3] ~= '' then redis.call('SADD', 'effectd:jobs:key:' .. ARGV[at + 3], id) end
  return 1
end
)";

// ARGV: id, worker, effect, key, created, fraction, cells, steps, leaseMs -> 1 made again, 0 there
constexpr const char* kRegister = R"(return register(1))";

// ARGV: id, worker, state (done or failed), status, headers, body, ttlMs, then kRegister's from
// its effect -> 1, or 0 when the job is no longer this worker's. A job Redis lost is made again
// first. A job asked to cancel ends cancelled, its answer not kept.
constexpr const char* kFinish = R"(
register(8)
local h = jobKey(ARGV[1])
local v = redis.call('HMGET', h, 'state', 'worker', 'cancel')
if v[1] ~= 'running' or v[2] ~= ARGV[2] then return 0 end
if v[3] == '1' then finish(ARGV[1], 'cancelled', '', '', '', now(), tonumber(ARGV[7]))
else finish(ARGV[1], ARGV[3], ARGV[4], ARGV[5], ARGV[6], now(), tonumber(ARGV[7])) end
return 1
)";

// ARGV: id, worker: a stopping replica's running job, back at the head of the queue.
constexpr const char* kRequeue = R"(
local h = jobKey(ARGV[1])
local v = redis.call('HMGET', h, 'state', 'worker')
if v[1] ~= 'running' or v[2] ~= ARGV[2] then return 0 end
redis.call('HSET', h, 'state', 'queued', 'queued', now(), 'fraction', '0', 'cells', 0, 'steps', 0)
redis.call('HDEL', h, 'worker', 'lease', 'started')
redis.call('HINCRBY', h, 'version', 1)
redis.call('SREM', 'effectd:jobs:running', ARGV[1])
redis.call('LPUSH', 'effectd:jobs:queue', ARGV[1])
return 1
)";

// ARGV: worker, leaseMs, ttlMs, maxAttempts, problem, ids...: this worker's leases renewed, and
// every running job whose lease ran out queued again (or failed) -> {how many were reaped, the
// ids of this worker's that Redis no longer has...}.
constexpr const char* kHeartbeatScript = R"(
local t = now()
local missing = {}
for i = 6, #ARGV do
  local h = jobKey(ARGV[i])
  local v = redis.call('HMGET', h, 'state', 'worker')
  if v[1] == 'running' and v[2] == ARGV[1] then redis.call('HSET', h, 'lease', t + tonumber(ARGV[2]))
  elseif redis.call('EXISTS', h) == 0 then table.insert(missing, ARGV[i]) end
end
local reaped = 0
for _, id in ipairs(redis.call('SMEMBERS', 'effectd:jobs:running')) do
  local h = jobKey(id)
  local v = redis.call('HMGET', h, 'state', 'lease', 'attempts')
  if v[1] ~= 'running' then
    redis.call('SREM', 'effectd:jobs:running', id)
  elseif (tonumber(v[2]) or 0) < t then
    reaped = reaped + 1
    local attempts = (tonumber(v[3]) or 0) + 1
    redis.call('HSET', h, 'attempts', attempts)
    if attempts >= tonumber(ARGV[4]) then
      finish(id, 'failed', '500', '{"Content-Type":"application/problem+json"}', ARGV[5], t, tonumber(ARGV[3]))
    else
      redis.call('HSET', h, 'state', 'queued', 'queued', t, 'fraction', '0', 'cells', 0, 'steps', 0)
      redis.call('HDEL', h, 'worker', 'lease', 'started')
      redis.call('HINCRBY', h, 'version', 1)
      redis.call('SREM', 'effectd:jobs:running', id)
      redis.call('RPUSH', 'effectd:jobs:queue', id)
    end
  end
end
return {reaped, unpack(missing)}
)";

// ARGV: id, ttlMs -> the state before (nil: no such job)
constexpr const char* kCancel = R"(
local h = jobKey(ARGV[1])
local s = redis.call('HGET', h, 'state')
if not s then return false end
if s == 'queued' then
  redis.call('LREM', 'effectd:jobs:queue', 0, ARGV[1])
  redis.call('HSET', h, 'cancel', '1')
  finish(ARGV[1], 'cancelled', '', '', '', now(), tonumber(ARGV[2]))
elseif s == 'running' then
  redis.call('HSET', h, 'cancel', '1')
  redis.call('HINCRBY', h, 'version', 1)
end
return s
)";

// ARGV: id -> 1 forgotten, 0 not finished or not there
constexpr const char* kRemove = R"(
local s = redis.call('HGET', jobKey(ARGV[1]), 'state')
if s ~= 'done' and s ~= 'failed' and s ~= 'cancelled' then return 0 end
redis.call('DEL', jobKey(ARGV[1]))
redis.call('ZREM', 'effectd:jobs:all', ARGV[1])
return 1
)";

// -> {queued, running, kept, done, failed, cancelled}
constexpr const char* kCounts = R"(
redis.call('ZREMRANGEBYSCORE', 'effectd:jobs:all', '-inf', now())
local out = {redis.call('LLEN', 'effectd:jobs:queue'), redis.call('SCARD', 'effectd:jobs:running'),
             redis.call('ZCARD', 'effectd:jobs:all')}
for _, s in ipairs({'done', 'failed', 'cancelled'}) do
  table.insert(out, tonumber(redis.call('GET', 'effectd:jobs:finished:' .. s) or '0'))
end
return out
)";

std::optional<JobState> stateOf(const std::string& s) {
  for (JobState j : {JobState::kQueued, JobState::kRunning, JobState::kDone, JobState::kFailed, JobState::kCancelled})
    if (s == toString(j)) return j;
  return std::nullopt;
}

double number(const RedisReply& r) { return r.isString() ? std::strtod(r.text.c_str(), nullptr) : 0.0; }

std::string workerName() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return std::string(host) + ":" + std::to_string(getpid()) + ":" + newRequestId().substr(0, 8);
}

class RedisJobs final : public Jobs {
 public:
  RedisJobs(Options options, Runner runner, const std::string& url)
      : o_(options), runner_(std::move(runner)), control_(url, std::chrono::seconds(2)),
        work_(url, std::chrono::seconds(2)), worker_(workerName()) {
    for (int i = 0; i < o_.workers; ++i) threads_.emplace_back([this] { work(); });
    threads_.emplace_back([this] { heartbeat(); });
  }
  ~RedisJobs() override { stop(); }

  JobView submit(const std::string& effect, std::string body, const std::string& keyId, Refusal& refusal) override {
    const std::string id = newJobId();
    const RedisReply r = eval(control_, kSubmit, {id, effect, keyId, body, std::to_string(o_.maxJobs), std::to_string(o_.perKey)});
    refusal = r.text == "full" ? Refusal::kFull : r.text == "busy" ? Refusal::kKeyBusy : Refusal::kNone;
    if (refusal != Refusal::kNone) return {};
    if (auto v = find(id, false)) return *v;
    throw JobStoreError("the job store lost a job it had just queued");
  }

  std::optional<JobView> find(const std::string& id, bool withBody) override {
    const RedisReply r = eval(control_, kView, {id, withBody ? "1" : "0"});
    if (r.type != RedisReply::Type::kArray || r.items.size() != 3 || r.items[0].items.size() != 15)
      return std::nullopt;
    const std::vector<RedisReply>& f = r.items[0].items;
    const double now = double(r.items[1].integer);
    const auto state = stateOf(f[2].text);
    if (!state) return std::nullopt;
    JobView v;
    v.id = id, v.effect = f[0].text, v.keyId = f[1].text, v.state = *state;
    v.fraction = number(f[3]), v.cells = size_t(number(f[4])), v.steps = size_t(number(f[5]));
    const double created = number(f[6]), queued = number(f[7]), started = number(f[8]), ended = number(f[9]);
    v.created = std::chrono::system_clock::time_point(std::chrono::milliseconds(static_cast<long long>(created)));
    const bool over = finished(v.state), begun = f[8].isString();
    v.queuedS = ((begun ? started : over ? ended : now) - queued) / 1000;
    if (begun) v.runningS = ((over ? ended : now) - started) / 1000;
    if (v.state == JobState::kRunning && v.fraction >= 0.02) v.etaS = v.runningS * (1 - v.fraction) / v.fraction;
    if (over) v.etaS = 0;
    v.cancelRequested = f[10].text == "1";
    v.version = uint64_t(number(f[11]));
    v.worker = f[12].text;
    if (f[13].isString()) {
      auto a = std::make_shared<JobAnswer>();
      a->status = int(number(f[13]));
      try {
        const nlohmann::json headers = nlohmann::json::parse(f[14].text);  // items() must not outlive it
        for (const auto& [name, value] : headers.items()) a->headers[name] = value.get<std::string>();
      } catch (const std::exception&) {
      }
      if (r.items[2].isString()) a->body = r.items[2].text;
      v.answer = std::move(a);
    }
    return v;
  }

  std::optional<JobView> waitForChange(const std::string& id, uint64_t version, std::chrono::milliseconds timeout) override {
    const auto until = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      std::optional<JobView> v = find(id, false);
      if (!v || v->version != version || std::chrono::steady_clock::now() >= until || stopping_) return v;
      std::this_thread::sleep_for(kWatchPoll);
    }
  }

  std::optional<JobView> cancel(const std::string& id, std::chrono::milliseconds wait) override {
    const RedisReply r = eval(control_, kCancel, {id, std::to_string(ttlMs())});
    if (!r.isString()) return std::nullopt;
    const auto until = std::chrono::steady_clock::now() + wait;
    for (;;) {  // the worker, wherever it runs, stops at its next progress report
      std::optional<JobView> v = find(id, false);
      if (!v || finished(v->state) || std::chrono::steady_clock::now() >= until) return v;
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
  }

  bool remove(const std::string& id) override { return eval(control_, kRemove, {id}).integer == 1; }

  void stop() override {
    {
      std::lock_guard lock(mu_);
      if (stopping_) return;
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_)
      if (t.joinable()) t.join();
    threads_.clear();
  }

  std::string metricsText() const override {
    std::string out = "# HELP effectd_jobs Jobs kept, by state (in the shared store).\n# TYPE effectd_jobs gauge\n";
    std::optional<RedisReply> r = control_.command({"EVAL", std::string(kPrelude) + kCounts, "0"});
    if (!r || r->type != RedisReply::Type::kArray || r->items.size() != 6)
      return out + "# the job store (Redis) did not answer\n";
    const auto n = [&](size_t i) { return r->items[i].integer; };
    out += "effectd_jobs{state=\"queued\"} " + std::to_string(n(0)) + "\neffectd_jobs{state=\"running\"} " +
           std::to_string(n(1)) + "\neffectd_jobs{state=\"finished\"} " + std::to_string(std::max(0LL, n(2) - n(0) - n(1))) +
           "\n# HELP effectd_jobs_finished_total Jobs finished, by how (every replica's).\n"
           "# TYPE effectd_jobs_finished_total counter\n";
    const char* states[] = {"done", "failed", "cancelled"};
    for (size_t i = 0; i < 3; ++i)
      out += std::string("effectd_jobs_finished_total{state=\"") + states[i] + "\"} " + std::to_string(n(3 + i)) + "\n";
    return out + "# HELP effectd_jobs_registered_again_total Running jobs this replica registered again after the "
                 "job store lost them.\n# TYPE effectd_jobs_registered_again_total counter\n"
                 "effectd_jobs_registered_again_total " + std::to_string(registered_.load()) + "\n";
  }

  bool shared() const override { return true; }
  // From the last exchanges, without one of its own: the heartbeat talks to Redis every
  // kHeartbeat, and a probe must answer within its timeout (a blackholed Redis takes 2 s).
  std::string storeProblem() override {
    const std::string work = work_.lastProblem();
    return work.empty() ? control_.lastProblem() : work;
  }
  uint64_t storeFailures() const override { return control_.failures() + work_.failures(); }
  bool settling() override {  // within a lease of Redis's start: every heartbeat has had its turn
    const auto r = control_.command({"INFO", "server"});
    if (!r || !r->isString()) return false;
    const size_t at = r->text.find("uptime_in_seconds:");
    return at != std::string::npos &&
           std::strtoll(r->text.c_str() + at + 18, nullptr, 10) < std::chrono::seconds(kLease).count();
  }

 private:
  long long ttlMs() const { return static_cast<long long>(o_.ttl.count()) * 1000; }

  // A script's reply; an unreachable Redis or an error reply is a JobStoreError.
  static RedisReply eval(RedisClient& client, const char* script, const std::vector<std::string>& argv) {
    std::vector<std::string> args = {"EVAL", std::string(kPrelude) + kRegisterFn + script, "0"};
    args.insert(args.end(), argv.begin(), argv.end());
    std::optional<RedisReply> r = client.command(args);
    if (!r) throw JobStoreError("the job store (Redis) did not answer");
    if (r->type == RedisReply::Type::kError) throw JobStoreError("the job store (Redis): " + r->text);
    return *r;
  }

  bool idle(std::chrono::milliseconds d) {
    std::unique_lock lock(mu_);
    return !wake_.wait_for(lock, d, [&] { return stopping_.load(); });
  }

  void work() {
    while (!stopping_) {
      RedisReply claimed;
      try {
        claimed = eval(work_, kClaim, {worker_, std::to_string(std::chrono::milliseconds(kLease).count())});
      } catch (const JobStoreError&) {
        if (!idle(std::chrono::seconds(1))) return;
        continue;
      }
      if (claimed.type != RedisReply::Type::kArray || claimed.items.size() != 5) {
        if (!idle(kIdlePoll)) return;
        continue;
      }
      const std::string id = claimed.items[0].text, effect = claimed.items[1].text, body = claimed.items[2].text;
      {
        std::lock_guard lock(mu_);
        mine_[id] = {effect, claimed.items[3].text, claimed.items[4].text, "0", "0", "0"};
      }
      const JobProgress progress = [this, id](double fraction, size_t cells, size_t steps) {
        if (stopping_) return false;
        char f[32];
        std::snprintf(f, sizeof f, "%.6f", std::clamp(fraction, 0.0, 1.0));
        {
          std::lock_guard lock(mu_);
          Held& held = mine_[id];
          held.fraction = f, held.cells = std::to_string(cells), held.steps = std::to_string(steps);
        }
        try {
          const long long go =
              eval(work_, kProgress, withRegistration({id, worker_, f, std::to_string(cells), std::to_string(steps)}, id))
                  .integer;
          if (go == 2) ++registered_;
          return go >= 1;
        } catch (const JobStoreError&) {
          return true;  // Redis away for a moment: the work goes on, the lease may still hold
        }
      };
      JobAnswer answer;
      try {
        answer = runner_(effect, body, progress);
      } catch (const std::exception&) {
        answer.status = 500;
        answer.headers["Content-Type"] = "application/problem+json";
        answer.body = std::string("{\"type\":\"https://effectd.dev/problems/internal\",\"title\":\"Internal Server "
                                  "Error\",\"status\":500,\"detail\":\"the job failed\"}");
      }
      // Stopped by this replica's stop (a cancelled bolt's 409, or admission's 503 given up):
      // back to the queue for another replica. A job that ended on its own is recorded, once
      // Redis answers (the heartbeat keeps its lease meanwhile); a replica stopping first drops
      // it, and the lease runs out for another replica to run it again.
      const bool requeue = stopping_ && (answer.status == 409 || answer.status == 503);
      for (;;) {
        try {
          if (requeue) {
            eval(work_, kRequeue, {id, worker_});
          } else {
            nlohmann::json headers = answer.headers;
            eval(work_, kFinish,
                 withRegistration({id, worker_, answer.status < 400 ? "done" : "failed", std::to_string(answer.status),
                                   headers.dump(), answer.body, std::to_string(ttlMs())},
                                  id));
          }
          break;
        } catch (const JobStoreError&) {
          if (requeue || !idle(std::chrono::seconds(1))) break;
        }
      }
      std::lock_guard lock(mu_);
      mine_.erase(id);
    }
  }

  void heartbeat() {
    const std::string problem =
        "{\"type\":\"https://effectd.dev/problems/internal\",\"title\":\"Internal Server Error\",\"status\":500,"
        "\"detail\":\"the replicas that ran this job stopped answering " +
        std::to_string(kMaxAttempts) + " times\"}";
    while (idle(std::chrono::duration_cast<std::chrono::milliseconds>(kHeartbeat))) {
      std::vector<std::string> argv = {worker_, std::to_string(std::chrono::milliseconds(kLease).count()),
                                       std::to_string(ttlMs()), std::to_string(kMaxAttempts), problem};
      {
        std::lock_guard lock(mu_);
        for (const auto& [id, held] : mine_) argv.push_back(id);
      }
      try {
        const RedisReply r = eval(work_, kHeartbeatScript, argv);
        for (size_t i = 1; i < r.items.size(); ++i)  // jobs Redis lost: registered again
          if (eval(work_, kRegister, registration(r.items[i].text)).integer == 1) ++registered_;
      } catch (const JobStoreError&) {
      }
    }
  }

  // kRegister's arguments for a job this replica runs: what it was, and its progress so far.
  std::vector<std::string> registration(const std::string& id) {
    std::lock_guard lock(mu_);
    const Held& h = mine_[id];
    return {id, worker_, h.effect, h.key, h.created, h.fraction, h.cells, h.steps,
            std::to_string(std::chrono::milliseconds(kLease).count())};
  }
  // A script's own arguments followed by kRegister's (kProgress, kFinish make a lost job again).
  std::vector<std::string> withRegistration(std::vector<std::string> argv, const std::string& id) {
    const std::vector<std::string> again = registration(id);
    argv.insert(argv.end(), again.begin(), again.end());
    return argv;
  }

  const Options o_;
  const Runner runner_;
  mutable RedisClient control_;  // the routes' reads and changes
  RedisClient work_;             // the workers' and the heartbeat's
  const std::string worker_;
  std::mutex mu_;
  std::condition_variable wake_;
  std::atomic<bool> stopping_{false};
  struct Held {  // a job this replica's workers run, as kRegister makes it again
    std::string effect, key, created, fraction, cells, steps;
  };
  std::map<std::string, Held> mine_;
  std::atomic<uint64_t> registered_{0};  // jobs registered again after Redis lost them
  std::vector<std::thread> threads_;
};

}  // namespace

std::unique_ptr<Jobs> Jobs::inRedis(Options options, Runner runner, const std::string& redisUrl) {
  return std::make_unique<RedisJobs>(options, std::move(runner), redisUrl);
}

}  // namespace effectd
