// The jobs' routes (docs/api.md, "Jobs"): POST /v1/jobs and an effect's POST with Prefer:
// respond-async queue a request; GET /v1/jobs/{id} is its state and progress, /events the same
// as Server-Sent Events, /result the answer once done; DELETE cancels (or forgets a finished
// job). A job runs its request as the effect's endpoint does (Service::answer) under the job
// limits (--max-job-grid-cells ...), so its answer is the synchronous one, ETag included; it is
// priced and charged to the API key when it is queued, and admitted to the memory budget when
// it runs.
#include <httplib.h>

#include <ctime>

#include "contract/json_reader.h"
#include "http/access.h"
#include "http/connections.h"
#include "http/etag.h"
#include "http/quota.h"
#include "http/request_state.h"
#include "http/route.h"
#include "http/service.h"
#include "http/streams.h"

namespace effectd {

using nlohmann::json;

namespace {

constexpr const char* kJobsPath = "/v1/jobs";

std::string rfc3339(std::chrono::system_clock::time_point t) {
  const std::time_t s = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char out[32];
  std::strftime(out, sizeof out, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return out;
}

json statusJson(const JobView& v) {
  const std::string self = std::string(kJobsPath) + "/" + v.id;
  json links = {{"self", self}, {"events", self + "/events"}};
  if (v.answer) links["result"] = self + "/result";
  json out = {{"id", v.id},
              {"effect", v.effect},
              {"state", toString(v.state)},
              {"progress",
               {{"fraction", v.fraction},
                {"cells", v.cells},
                {"steps", v.steps},
                {"etaS", v.etaS >= 0 ? json(v.etaS) : json(nullptr)}}},
              {"created", rfc3339(v.created)},
              {"queuedS", v.queuedS},
              {"runningS", v.runningS},
              {"links", links}};
  if (v.cancelRequested && !finished(v.state)) out["cancelRequested"] = true;
  if (!v.worker.empty()) out["worker"] = v.worker;
  if (v.expired) out["expired"] = true;
  if (v.state == JobState::kFailed && v.answer) {
    try {
      out["error"] = readJson(v.answer->body);
    } catch (const std::exception&) {
      out["error"] = {{"status", v.answer->status}};
    }
  }
  return out;
}

void sendStatus(const JobView& v, int status, httplib::Response& res) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  res.set_content(statusJson(v).dump(), "application/json");
}

ApiError notFound(const std::string& id) {
  return {404, "not-found", "Not Found", "no job " + id + " here (finished jobs are kept for --job-ttl)", {}, {}};
}

// An id this service made that no store holds: deleted, expired, or lost with the store.
ApiError gone(const std::string& id, long long madeAt, int ttlS) {
  const long long age = std::max(0LL, (long long)std::time(nullptr) - madeAt);
  const std::string why =
      age > ttlS ? "it was made " + std::to_string(age) + " s ago, and a finished job is kept for --job-ttl (" +
                       std::to_string(ttlS) + " s)"
                 : "it was deleted, or the job store lost it (a Redis restarted without its data, or a replica's "
                   "own store with its process): submit it again";
  return {410, "gone", "Gone", "job " + id + " is no longer here: " + why, {}, {}};
}

ApiError storeDown(const JobStoreError& e) {
  return {503, "unavailable", "Service Unavailable", std::string(e.what()) + " (--jobs-redis)", {}, {{"Retry-After", "5"}}};
}

}  // namespace

void Service::installJobs() {
  jobConfig_ = config_;
  jobConfig_.limits.maxSolverGridCells = std::max(config_.maxJobGridCells, config_.limits.maxSolverGridCells);
  jobConfig_.limits.maxSolverVolumeCells = std::max(config_.maxJobVolumeCells, config_.limits.maxSolverVolumeCells);
  jobConfig_.limits.solverGridKnob = "--max-job-grid-cells";
  jobConfig_.limits.solverVolumeKnob = "--max-job-volume-cells";
  jobConfig_.limits.jobsTakeMore = false;
  Jobs::Options o;
  o.workers = config_.jobWorkers;
  o.maxJobs = size_t(config_.maxJobs);
  o.ttl = std::chrono::seconds(config_.jobTtlS);
  o.maxStoreBytes = config_.jobStoreMb << 20;
  o.perKey = config_.keyMaxJobs;
  Jobs::Runner runner = [this](const std::string& effect, const std::string& body, const JobProgress& progress) {
    return runJob(effect, body, progress);
  };
  jobs_ = config_.jobsRedis.empty() ? Jobs::inProcess(o, std::move(runner))
                                    : Jobs::inRedis(o, std::move(runner), config_.jobsRedis);
  metrics_.addSource([this] { return jobs_->metricsText(); });
  if (jobs_->shared())  // --jobs-redis: synchronous requests go on without it, jobs do not
    addDegradedCheck("jobStore", [this] {
      const std::string why = jobs_->storeProblem();
      return why.empty() ? why : "--jobs-redis " + why + ": jobs answer 503 until it is back";
    });

  auto route = [this](const std::string& path, std::vector<std::string> methods) {
    auto r = std::make_unique<Route>();
    r->path = path;
    r->methods = std::move(methods);
    r->jobs = true;
    routes_.push_back(std::move(r));
  };
  route(kJobsPath, {"POST"});
  route(std::string(kJobsPath) + "/", {"GET", "HEAD", "DELETE"});  // stands for every job below it
  http_->Post(kJobsPath, [this](const httplib::Request& req, httplib::Response& res) {
    try {
      Stages stages;
      json body;
      parseJsonRequest(req.body, *schemas_, "job.json", body, stages);
      const std::string effect = body["effect"];
      const Route* target = findRoute("/v1/" + effect);
      if (!target || !target->json)
        throw ApiError{400, "invalid-field", "Invalid field", "/effect: no such effect", {{"/effect", "no such effect"}}, {}};
      submitJob(*target, body["request"].dump(), res, "/request");
    } catch (const ApiError& e) {
      writeProblem(res, e, tl.requestId);
    }
  });
  const std::string id = std::string(kJobsPath) + "/([0-9a-f]+)";
  http_->Get(id, [this](const httplib::Request& req, httplib::Response& res) { answerJobStatus(req, res); });
  http_->Get(id + "/events", [this](const httplib::Request& req, httplib::Response& res) { answerJobEvents(req, res); });
  http_->Get(id + "/result", [this](const httplib::Request& req, httplib::Response& res) { answerJobResult(req, res); });
  http_->Delete(id, [this](const httplib::Request& req, httplib::Response& res) { cancelJob(req, res); });
}

void Service::submitJob(const Route& route, const std::string& bodyText, httplib::Response& res,
                        const std::string& at) {
  try {
    if (tl.key && !tl.key->allows(route.path))
      throw ApiError{403, "forbidden", "Forbidden", "the API key '" + tl.key->id + "' is not allowed on " + route.path,
                     {}, {}};
    // Checked and priced now, under the job limits: a request the endpoint would refuse is
    // refused here, and the key pays for its estimate before the job is queued.
    Stages stages;
    json body;
    parseJsonRequest(bodyText, *schemas_, route.schema, body, stages);
    RequestContext ctx{tl.requestId, jobConfig_, compute_.get()};
    const PreparedRequest prepared = route.json(body, ctx);
    const Admission::Counts budget = admission_->counts();
    if (prepared.cost.bytes > budget.budgetBytes)
      throw ApiError{413, "too-large", "Payload Too Large",
                     "the job would need " + std::to_string(prepared.cost.bytes >> 20) + " MiB at its peak, over the " +
                         std::to_string(budget.budgetBytes >> 20) + " MiB memory budget (--memory-budget-mb)",
                     {}, {}};
    Jobs::Refusal refusal;
    JobView v;
    try {
      v = jobs_->submit(route.path.substr(4), bodyText, tl.keyId, refusal);
    } catch (const JobStoreError& e) {
      throw storeDown(e);
    }
    if (refusal == Jobs::Refusal::kFull)
      throw ApiError{503, "overloaded", "Service Unavailable",
                     "the server keeps " + std::to_string(config_.maxJobs) + " jobs and " +
                         std::to_string(config_.jobStoreMb) + " MiB of their requests and answers at most "
                         "(--max-jobs, --job-store-mb), or is stopping",
                     {}, {{"Retry-After", "10"}}};
    if (refusal == Jobs::Refusal::kKeyBusy)
      throw ApiError{429, "too-many-jobs", "Too Many Requests",
                     "the API key has " + std::to_string(config_.keyMaxJobs) +
                         " jobs queued or running, its most (--key-max-jobs): wait for one to finish",
                     {}, {{"Retry-After", "10"}}};
    if (tl.key) {
      access_->charge(*tl.key, quotaUnits(prepared.cost.bytes + tl.bodyTicket.bytes()), res);
      tl.keyCharged = true;
    }
    res.set_header("Location", std::string(kJobsPath) + "/" + v.id);
    res.set_header("Preference-Applied", "respond-async");
    sendStatus(v, 202, res);
  } catch (ApiError& e) {
    if (tl.key && !tl.keyCharged && e.status >= 400 && e.status < 500 && e.status != 429)
      access_->chargeInvalid(*tl.key, bodyText.size());
    for (FieldError& f : e.errors) f.pointer = at + f.pointer;  // where the request sits in the body
    if (!at.empty() && !e.detail.empty() && e.detail[0] == '/') e.detail = at + e.detail;
    writeProblem(res, e, tl.requestId);
  }
}

JobAnswer Service::runJob(const std::string& effect, const std::string& body, const JobProgress& progress) {
  const Route* route = findRoute("/v1/" + effect);
  for (;;) {
    tl = RequestState{};
    tl.requestId = newRequestId();
    tl.route = route->path;
    httplib::Response res;
    answer(*route, body, "application/json", {}, "", res, jobConfig_, progress);
    tl = RequestState{};  // the reservations go: the answer is in hand
    // Admission refused it for now (memory or heavy slots busy past the wait): a job waits on.
    if (res.status == 503 && progress(0, 0, 0) && !stopping_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      continue;
    }
    JobAnswer a;
    a.status = res.status < 0 ? 200 : res.status;
    for (const auto& [name, value] : res.headers)
      if (name != "X-Request-ID") a.headers[name] = value;
    a.body = std::move(res.body);
    return a;
  }
}

std::optional<JobView> Service::jobOf(const httplib::Request& req, httplib::Response& res, bool withBody) {
  const std::string id = req.matches[1];
  std::optional<JobView> v;
  try {
    v = jobs_->find(id, withBody);
  } catch (const JobStoreError& e) {
    writeProblem(res, storeDown(e), tl.requestId);
    return std::nullopt;
  }
  if (v && v->keyId != tl.keyId) {  // another key's job is not there for this one
    writeProblem(res, notFound(id), tl.requestId);
    return std::nullopt;
  }
  if (!v) {
    const auto made = jobIdTime(id);
    if (made && jobs_->settling())
      writeProblem(res, storeDown(JobStoreError("the job store (Redis) restarted moments ago and the replicas are "
                                                "registering their running jobs again")), tl.requestId);
    else
      writeProblem(res, made ? gone(id, *made, config_.jobTtlS) : notFound(id), tl.requestId);
  }
  return v;
}

void Service::answerJobStatus(const httplib::Request& req, httplib::Response& res) {
  if (auto v = jobOf(req, res)) sendStatus(*v, 200, res);
}

void Service::answerJobEvents(const httplib::Request& req, httplib::Response& res) {
  // A stream holds its connection and thread while the job runs: one of the client's share
  // first (http/streams.h), and none at all on a connection past --max-connections; then the
  // connection is counted among the streams, not the connections requests need.
  std::shared_ptr<void> place;
  const std::string client = tl.key ? "key " + tl.key->id : "address " + req.remote_addr;
  const int most = tl.key ? (tl.key->maxStreams > 0 ? tl.key->maxStreams : config_.keyMaxStreams)
                          : config_.maxStreamsPerAddress;
  const std::string whose = tl.key ? "the key '" + tl.key->id + "' (" +
                                         (tl.key->maxStreams > 0 ? "its maxStreams" : "--key-max-streams") + ")"
                                   : "the address " + req.remote_addr + " (--max-streams-per-address)";
  if (auto problem = streams_->enter(client, most, whose, place)) return writeProblem(res, *problem, tl.requestId);
  if (EdgeServer::overCapacity()) return writeProblem(res, EdgeServer::overCapacityProblem(), tl.requestId);
  // From here the connection is the stream's, not one of --max-connections.
  place = std::make_shared<std::pair<std::shared_ptr<void>, std::shared_ptr<void>>>(std::move(place), http_->holdAsStream());
  auto first = jobOf(req, res);
  if (!first) return;
  // One event per change: "progress" while queued or running, then one named by the final
  // state, and the stream ends. A comment every 15 s keeps proxies from closing a quiet one.
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Accel-Buffering", "no");  // nginx: pass each event on at once
  const std::string id = first->id;
  auto last = std::make_shared<uint64_t>(~uint64_t(0));
  auto quiet = std::make_shared<int>(0);
  res.set_chunked_content_provider("text/event-stream", [this, id, last, quiet, place](size_t, httplib::DataSink& sink) {
    std::optional<JobView> v;
    try {
      v = *last == ~uint64_t(0) ? jobs_->find(id) : jobs_->waitForChange(id, *last, std::chrono::milliseconds(1000));
    } catch (const JobStoreError&) {  // the store went away: the stream ends, the client asks again
    }
    if (!v || stopping_) {
      sink.done();
      return true;
    }
    std::string out;
    if (v->version == *last) {
      if (++*quiet < 15) return true;
      *quiet = 0;
      out = ": still " + std::string(toString(v->state)) + "\n\n";
    } else {
      *last = v->version;
      *quiet = 0;
      out = "event: " + std::string(finished(v->state) ? toString(v->state) : "progress") + "\nid: " +
            std::to_string(v->version) + "\ndata: " + statusJson(*v).dump() + "\n\n";
    }
    if (!sink.write(out.data(), out.size())) return false;
    if (finished(v->state)) sink.done();
    return true;
  });
}

void Service::answerJobResult(const httplib::Request& req, httplib::Response& res) {
  auto v = jobOf(req, res, true);
  if (!v) return;
  res.set_header("Cache-Control", "no-store");
  if (v->answer) {
    const JobAnswer& a = *v->answer;
    auto tag = a.headers.find("ETag");
    if (a.status == 200 && tag != a.headers.end() && etagMatches(req.get_header_value("If-None-Match"), tag->second)) {
      res.set_header("ETag", tag->second);
      res.status = 304;
      return;
    }
    for (const auto& [name, value] : a.headers)
      if (name != "Content-Type" && name != "Content-Length") res.set_header(name, value);
    res.status = a.status;
    tl.encoded = true;  // sent as stored (identity): its ETag names these bytes, not a coding of them
    auto type = a.headers.find("Content-Type");
    res.set_content(a.body, type == a.headers.end() ? "application/octet-stream" : type->second);
    return;
  }
  const std::string self = std::string(kJobsPath) + "/" + v->id;
  if (v->expired)
    return writeProblem(res,
                        {410, "expired", "Gone",
                         "the job's answer was dropped to keep others (--job-store-mb): submit it again", {}, {}},
                        tl.requestId);
  if (v->state == JobState::kCancelled)
    return writeProblem(res, {409, "cancelled", "Conflict", "the job was cancelled", {}, {}}, tl.requestId);
  writeProblem(res,
               {409, "not-finished", "Conflict",
                std::string("the job is ") + toString(v->state) + ": follow " + self + "/events or poll " + self,
                {}, {{"Retry-After", "1"}, {"Location", self}}},
               tl.requestId);
}

void Service::cancelJob(const httplib::Request& req, httplib::Response& res) {
  auto v = jobOf(req, res);
  if (!v) return;
  try {
    if (finished(v->state)) {  // a finished job: forgotten, its answer's memory returned
      jobs_->remove(v->id);
      res.status = 204;
      return;
    }
    // The work stops at its next progress report (a bolt reports every 50 ms); waited for here.
    if (auto after = jobs_->cancel(v->id, std::chrono::milliseconds(2000))) sendStatus(*after, 200, res);
  } catch (const JobStoreError& e) {
    writeProblem(res, storeDown(e), tl.requestId);
  }
}

}  // namespace effectd
