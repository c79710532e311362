// The HTTP service: routing, request ids, limits, problem+json errors, access log, metrics.
// Effect endpoints plug in through addJsonEndpoint(); they never see HTTP details beyond the
// parsed, schema-validated body, and they report bad input by throwing ApiError.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/parallel.h>

#include "contract/config.h"
#include "contract/problem.h"
#include "contract/schema.h"
#include "http/admission.h"
#include "http/idle_trim.h"
#include "http/jobs.h"
#include "http/metrics.h"
#include "http/response_cache.h"

namespace effects {
struct Error;
struct Stats;
}  // namespace effects
namespace httplib {
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace effectd {

class Access;
class EdgeServer;
class Streams;

// Server-Timing entries (name;dur=ms), in order.
using Stages = std::vector<std::pair<std::string, double>>;

// What a JSON endpoint returns: the body, plus the stats whose timing goes to Server-Timing.
struct JsonReply {
  nlohmann::json body;
  double computeMs = 0;  // the method's own work
  double errorMs = 0;    // measuring its error against the reference (Server-Timing "error")
  std::string method;    // the method that ran, echoed in the X-Effect-Method header
  // A JSON request may answer with bytes of another media type instead (e.g. image/png).
  std::string binary, contentType;
  std::map<std::string, std::string> headers;     // part of the answer (cached with it)
  std::map<std::string, std::string> runHeaders;  // facts of this run (timings): not cached
  // Server-Timing entries after compute, in order: its parts, and waits.
  Stages stages;
};

// What a request will cost, estimated from its body before any work starts: the bytes it
// holds at its peak (inputs, working set, the answer as JSON and as sent) and whether it is
// heavy (seconds of CPU). Admission control reserves these (see admission.h).
struct Cost {
  size_t bytes = 0;
  bool heavy = false;
  Cost& operator+=(const Cost& o) {
    bytes += o.bytes;
    heavy = heavy || o.heavy;
    return *this;
  }
};

struct RequestContext {
  std::string requestId;
  const Config& config;
  effects::Parallel* parallel = nullptr;  // the process's compute threads, for work that splits
  // The JSON pointer, within the request body, of the object the handler reads: "" for an
  // endpoint's own body, "/fog" for the fog part of a /v1/scene. Problems name fields under it.
  std::string at = "";
  // The query string's parameters (binary bodies take their options there; JSON bodies have none).
  std::map<std::string, std::string> query = {};
  // Set when the work runs as a job (jobs.h): long work reports its progress and stops when
  // this says so.
  JobProgress progress = {};
};

// A JSON endpoint works in two steps. The first reads and checks the body's fields into the
// endpoint's typed request (work linear in the body: base64 decoded, a glTF's triangles read, a
// mesh's voxelisation work bounded; nothing voxelised, drawn or computed; what it holds is
// covered by the body's reservation, kJsonBodyFactor times its text) and says what
// running it will cost, from that request; the service admits the cost (admission.h), then
// calls `run`, which does the heavy work and answers.
struct PreparedRequest {
  Cost cost;
  std::function<JsonReply()> run;
};
using JsonEndpoint = std::function<PreparedRequest(const nlohmann::json& body, const RequestContext& ctx)>;
// The two steps of an endpoint: parse(body, ctx) -> its typed request R (cheap), cost(const R&,
// config), and run(const R&, body, ctx) (the body it came from, for what only shapes the answer).
template <class Parse, class CostOf, class Run>
JsonEndpoint twoSteps(Parse parse, CostOf cost, Run run) {
  return [parse, cost, run](const nlohmann::json& body, const RequestContext& ctx) {
    using R = std::decay_t<std::invoke_result_t<Parse, const nlohmann::json&, const RequestContext&>>;
    auto request = std::make_shared<const R>(parse(body, ctx));
    // body and ctx outlive run(): the service calls it before its own handler returns.
    return PreparedRequest{cost(*request, ctx.config),
                           [request, run, &body, &ctx] { return run(*request, body, ctx); }};
  };
}
// Binary request bodies (e.g. model/gltf-binary) -> a binary reply with a media type.
struct BinaryReply {
  std::string body;
  std::string contentType;
  double computeMs = 0;
  std::string method;
  std::map<std::string, std::string> headers;  // part of the answer (cached with it)
};
using BinaryHandler = std::function<BinaryReply(const std::string& body, const RequestContext& ctx)>;
using BinaryEstimator = std::function<Cost(const std::string& body, const Config& config)>;

class Service {
 public:
  explicit Service(Config config);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // POST `path` with an application/json body validated against proto/schemas/<schema>,
  // answered by `endpoint` (its cost admitted between its two steps).
  void addJsonEndpoint(const std::string& path, const std::string& schema, JsonEndpoint endpoint);
  // Lets `path` also accept a body of `contentType` (its own handler, no JSON Schema).
  void addBinaryAlternative(const std::string& path, const std::string& contentType, BinaryHandler handler,
                            BinaryEstimator cost);
  // GET/HEAD `path` answers `body` as `contentType` (static files: the playground). HTML gets a
  // Content-Security-Policy that allows only this origin's scripts, styles and requests.
  // An HTML page gets a Content-Security-Policy allowing scripts from itself and `scriptOrigin`
  // ("" = itself only).
  void addStatic(const std::string& path, const std::string& contentType, std::string body,
                 const std::string& scriptOrigin = "");
  // A component that must be up for /readyz; `probe` returns "" when ready, else why not.
  void addReadinessCheck(const std::string& name, std::function<std::string()> probe);
  // A component the service works without, less well (a shared store: jobs and quotas): /readyz
  // stays 200, says "degraded" and names it while `probe` says why.
  void addDegradedCheck(const std::string& name, std::function<std::string()> probe);
  // Responses carry a strong ETag: SHA-256 of the version, the route, the canonical request
  // and `salt()` (e.g. the renderer, when the answer depends on it); If-None-Match -> 304.
  void setEtagSalt(const std::string& path, std::function<std::string()> salt);
  // A fact /readyz reports under "info" (e.g. which renderer is in use).
  void addReadinessInfo(const std::string& name, std::function<std::string()> value);
  // SIGHUP: rereads the URL signing keys and the API keys (access.h). "" or why the old stay.
  std::string reloadAccess();

  int bind();       // binds host:port from the config; returns the port, or -1
  int adminPort() const { return adminPort_; }  // after bind(): the admin listener's, or 0
  size_t openConnections() const;                // on the public port
  bool run();       // serves until stop(); in-flight requests finish before it returns
  // Safe from any thread, also before run() has started serving: stops listening, closes the
  // connections idle or still sending, lets the requests being computed finish.
  void stop();
  bool waitUntilRunning(std::chrono::milliseconds timeout) const;

  const Config& config() const { return config_; }
  Metrics& metrics() { return metrics_; }
  const SchemaRegistry& schemas() const { return *schemas_; }
  Admission& admission() { return *admission_; }
  ResponseCache& responseCache() { return cache_; }

 private:
  struct Route;
  void installCore();
  void installHttpPolicy();
  bool preRoute(const httplib::Request& req, httplib::Response& res);  // http_policy.cpp
  void postRoute(const httplib::Request& req, httplib::Response& res);
  void finishRequest(const httplib::Request& req, const httplib::Response& res);
  void handlePost(const Route& route, const httplib::Request& req, httplib::Response& res);
  // GET <endpoint>?r=<base64url of the JSON body>: the POST's answer, cacheable by URL.
  void handleGet(const Route& route, const httplib::Request& req, httplib::Response& res);
  // The answer to `body` of media type `type` (both methods' and jobs' common path), under
  // `config`'s limits (config_, or jobConfig_ for a job, whose progress goes to `progress`).
  void answer(const Route& route, const std::string& body, const std::string& type,
              const std::map<std::string, std::string>& query, const std::string& inm, httplib::Response& res,
              const Config& config, const JobProgress& progress = {});
  // Jobs (jobs_api.cpp): the routes, queueing a request of `route` (POST /v1/jobs, or an effect's
  // POST with Prefer: respond-async), and running one.
  void installJobs();
  // `at`: where the request sits in the body that came ("/request" in POST /v1/jobs), for problems.
  void submitJob(const Route& route, const std::string& body, httplib::Response& res, const std::string& at = "");
  JobAnswer runJob(const std::string& effect, const std::string& body, const JobProgress& progress);
  void answerJobStatus(const httplib::Request& req, httplib::Response& res);
  void answerJobEvents(const httplib::Request& req, httplib::Response& res);
  void answerJobResult(const httplib::Request& req, httplib::Response& res);
  void cancelJob(const httplib::Request& req, httplib::Response& res);
  // The job a request's path names (its answer's bytes with `withBody`), if it is there and the
  // request's key (if any) owns it; otherwise the answer is a 404 problem (503: the store is away).
  std::optional<JobView> jobOf(const httplib::Request& req, httplib::Response& res, bool withBody = false);
  const Route* findRoute(const std::string& path) const;
  std::string allowedOrigin(const std::string& origin) const;  // "" when not allowed

  Config config_;
  Metrics metrics_;
  std::unique_ptr<Admission> admission_;
  ResponseCache cache_;
  std::unique_ptr<SchemaRegistry> schemas_;
  std::unique_ptr<EdgeServer> http_;
  std::unique_ptr<EdgeServer> admin_;  // --admin-port: health, readiness and metrics
  std::thread adminThread_;
  std::unique_ptr<effects::ThreadPool> compute_;  // shared by every request's parallel steps
  std::unique_ptr<Access> access_;                // who may ask, and how much
  std::unique_ptr<Streams> streams_;              // who holds the job event streams
  std::unique_ptr<IdleTrim> idleTrim_;
  int listenSocket_ = -1;  // the socket bind() made, so that its backlog can be raised
  int adminPort_ = 0;
  std::atomic<bool> stopping_{false};
  std::vector<std::unique_ptr<Route>> routes_;
  std::vector<std::pair<std::string, std::function<std::string()>>> readiness_, degraded_, info_;
  Config jobConfig_;            // config_ with the job limits in place of the request limits
  std::unique_ptr<Jobs> jobs_;  // last: its workers stop before what they use goes
};

// Writes `problem` into `res` as application/problem+json with the request id.
void writeProblem(httplib::Response& res, const ApiError& problem, const std::string& requestId);

}  // namespace effectd
