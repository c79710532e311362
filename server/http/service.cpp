// The service: routes, the contract documents, the POST path (cache, schema, ETag,
// admission, handler, coding) and the listening socket. The policy around every request is
// in http_policy.cpp.
#include "http/service.h"

#include <httplib.h>

#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <thread>

#include <sys/socket.h>

#include <effects/common.h>

#include "contract/codec.h"
#include "contract/json_reader.h"
#include "contract/json_writer.h"
#include "contract/resources.h"
#include "http/access.h"
#include "http/connections.h"
#include "http/elastic_pool.h"
#include "http/streams.h"
#include "http/encoding.h"
#include "http/etag.h"
#include "http/request_state.h"
#include "http/route.h"

namespace effectd {

using nlohmann::json;

namespace {

json parseBody(const std::string& body) {
  try {
    return readJson(body);
  } catch (const JsonSyntaxError& e) {
    if (e.tooDeep)
      throw ApiError{400,
                     "invalid-json",
                     "Malformed JSON",
                     "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels",
                     {{"", "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels"}},
                     {}};
    throw ApiError{400,
                   "invalid-json",
                   "Malformed JSON",
                   std::string("request body is not valid JSON: ") + e.what(),
                   {{e.pointer, "not valid JSON"}},
                   {}};
  }
}

// A JSON body that the route's schema refuses: a 400 problem naming the first violation and
// listing them all.
void throwIfInvalid(const std::vector<FieldError>& violations) {
  if (violations.empty()) return;
  const std::string& at = violations.front().pointer;
  std::string detail = (at.empty() ? std::string("the request body") : at) + ": " + violations.front().message;
  if (violations.size() > 1) detail += " (and " + std::to_string(violations.size() - 1) + " more)";
  throw ApiError{400, "invalid-field", "Request does not match the schema", detail, violations, {}};
}

}  // namespace

void parseJsonRequest(const std::string& text, const SchemaRegistry& schemas, const std::string& schema, json& body,
                      Stages& stages) {
  effects::Stopwatch parse;
  body = parseBody(text);
  stages.emplace_back("parse", parse.ms());
  effects::Stopwatch validate;
  throwIfInvalid(schemas.validate(schema, body));
  stages.emplace_back("validate", validate.ms());
}

namespace {

// What determines a JSON request's answer: its document's CBOR, one encoding per JSON value
// whatever the spacing, key order or number spelling, in a third of the time of the text.
std::string canonicalJson(const json& body) {
  std::string canonical = "application/json\n";
  json::to_cbor(body, canonical);
  return canonical;
}

// Writes `a` as the response, or a 304 when it carries an ETag that If-None-Match names.
void sendAnswer(const CachedAnswer& a, const std::string& inm, httplib::Response& res) {
  if (!a.etag.empty()) {  // "" = an answer with timings in it: no validator, never cached
    res.set_header("ETag", a.etag);
    if (etagMatches(inm, a.etag)) {
      res.status = 304;
      return;
    }
  }
  for (const auto& [name, value] : a.headers) res.set_header(name, value);
  if (!a.contentEncoding.empty()) res.set_header("Content-Encoding", a.contentEncoding);
  res.set_content(a.body, a.contentType);
}

// A header value in ASCII (RFC 9110 §5.5 leaves other bytes opaque, and clients mangle them):
// the report's row names write grids as 64², 32³, which go as 64^2, 32^3.
std::string asciiHeader(std::string value) {
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"\u00B2", "^2"}, {"\u00B3", "^3"}})
    for (size_t at = value.find(from); at != std::string::npos; at = value.find(from, at + to.size()))
      value.replace(at, from.size(), to);
  for (char& c : value)
    if (static_cast<unsigned char>(c) >= 0x80) c = '?';
  return value;
}

void addHeaders(std::map<std::string, std::string>& to, const std::map<std::string, std::string>& from) {
  for (const auto& [name, value] : from) to.emplace(name, asciiHeader(value));
}

// Runs a binary body's handler into `answer`; returns its compute time.
double answerBinary(const BinaryHandler& handler, const std::string& body, const RequestContext& ctx,
                    CachedAnswer& answer) {
  BinaryReply reply = handler(body, ctx);
  if (!reply.method.empty()) answer.headers["X-Effect-Method"] = reply.method;
  addHeaders(answer.headers, reply.headers);
  answer.body = std::move(reply.body);
  answer.contentType = reply.contentType;
  return reply.computeMs;
}

// Server-Timing's value: compute first, then the error measurement (when one ran), its stages,
// then the request's own (parse, validate, etag, write).
std::string serverTiming(double computeMs, const Stages& stages, const Stages& requestStages = {}, double errorMs = 0) {
  std::string timing = "compute;dur=" + std::to_string(computeMs);
  if (errorMs > 0) timing += ", error;dur=" + std::to_string(errorMs);
  for (const Stages* list : {&stages, &requestStages})
    for (const auto& [name, ms] : *list) timing += ", " + name + ";dur=" + std::to_string(ms);
  return timing;
}

// Runs a prepared JSON request into `answer` (JSON, or the bytes it answers with instead) and
// frees the request document; the run's own headers (Server-Timing included, with
// `requestStages` and the answer's writing after the run's own) go to `res` only.
void answerJson(const PreparedRequest& prepared, json& body, CachedAnswer& answer, httplib::Response& res,
                Stages requestStages) {
  JsonReply reply = prepared.run();
  body = json();  // the request document is no longer needed
  if (!reply.method.empty()) answer.headers["X-Effect-Method"] = reply.method;
  addHeaders(answer.headers, reply.headers);
  for (const auto& [name, value] : reply.runHeaders) res.set_header(name, asciiHeader(value));
  if (!reply.contentType.empty()) {
    answer.body = std::move(reply.binary);
    answer.contentType = reply.contentType;
  } else {
    effects::Stopwatch write;
    answer.body = writeJson(reply.body);
    answer.contentType = "application/json";
    requestStages.emplace_back("write", write.ms());
  }
  res.set_header("Server-Timing", serverTiming(reply.computeMs, reply.stages, requestStages, reply.errorMs));
}

// Encodes an answer worth compressing in the negotiated coding.
void encodeAnswer(Coding coding, CachedAnswer& answer) {
  if (coding != Coding::kIdentity && compressible(answer.contentType) && answer.body.size() >= kMinCompressBytes) {
    answer.body = encode(coding, answer.body);
    answer.contentEncoding = codingName(coding);
  }
}

using Probes = std::vector<std::pair<std::string, std::function<std::string()>>>;

// /readyz: each component "ready" or why not (503 when a readiness one is not; 200 and
// "degraded" when only a degraded one is not), and the info values.
void answerReadiness(const Probes& readiness, const Probes& degraded, const Probes& info, httplib::Response& res) {
  json components = json::object();
  bool ready = true, whole = true;
  for (const auto& [name, probe] : readiness) {
    std::string why = probe();
    components[name] = why.empty() ? json("ready") : json(why);
    ready = ready && why.empty();
  }
  for (const auto& [name, probe] : degraded) {
    std::string why = probe();
    components[name] = why.empty() ? json("ready") : json("degraded: " + why);
    whole = whole && why.empty();
  }
  json out = {{"status", !ready ? "not ready" : whole ? "ready" : "degraded"}, {"components", components}};
  for (const auto& [name, value] : info) out["info"][name] = value();
  res.status = ready ? 200 : 503;
  res.set_content(out.dump(), "application/json");
}

// /v1/schemas/<name>: a contract document.
void answerSchemaDocument(const httplib::Request& req, httplib::Response& res) {
  const std::string name = req.matches[1].str();
  auto it = resources().find("schemas/" + name);
  if (it == resources().end()) it = resources().find("schemas/" + name + ".json");  // /v1/schemas/fog
  if (it == resources().end()) {
    std::string known;
    for (const auto& [path, data] : resources())
      if (path.rfind("schemas/", 0) == 0) known += (known.empty() ? "" : ", ") + path.substr(8);
    writeProblem(res, {404, "not-found", "Not Found", "no schema " + name + "; there are: " + known, {}, {}},
                 tl.requestId);
    return;
  }
  res.set_content(std::string(it->second), "application/schema+json");
}

}  // namespace

namespace {
Admission::Options admissionOptions(const Config& c) {
  Admission::Options o;
  o.budgetBytes =
      c.memoryBudgetMb ? c.memoryBudgetMb << 20 : size_t(double(detectMemoryLimit().bytes) * kDefaultBudgetFraction);
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  o.heavySlots = c.heavyThreads > 0 ? c.heavyThreads : std::max(1, cores - 1);
  o.maxWaiting = c.admissionQueue;
  o.maxWait = std::chrono::milliseconds(c.admissionTimeoutMs);
  return o;
}
}  // namespace

Service::Service(Config config)
    : config_(std::move(config)),
      admission_(std::make_unique<Admission>(admissionOptions(config_))),
      cache_(config_.responseCacheMb << 20),
      http_(std::make_unique<EdgeServer>(config_.maxConnections)),
      compute_(std::make_unique<effects::ThreadPool>(effects::ThreadPool::besideCaller())),
      access_(std::make_unique<Access>(config_)),
      streams_(std::make_unique<Streams>(config_.maxStreams > 0 ? config_.maxStreams
                                                                : std::max(1, config_.maxConnections / 4))),
      idleTrim_(std::make_unique<IdleTrim>([this] { return admission_->counts().reservedBytes == 0; })) {
  std::map<std::string, std::string> docs;
  for (const auto& [name, data] : resources())
    if (name.rfind("schemas/", 0) == 0) docs[name.substr(8)] = std::string(data);
  schemas_ = std::make_unique<SchemaRegistry>(docs);
  installCore();
  installHttpPolicy();
  installJobs();
  metrics_.addSource([this] { return access_->metricsText(); });
  metrics_.addSource([this] { return streams_->metricsText(); });
  metrics_.addSource([this] {
    std::string out =
        "# HELP effectd_store_failures_total Exchanges with a shared store (Redis) that failed: unreachable, slow "
        "or not speaking RESP.\n# TYPE effectd_store_failures_total counter\n";
    if (jobs_->shared()) out += "effectd_store_failures_total{store=\"jobs\"} " + std::to_string(jobs_->storeFailures()) + "\n";
    if (access_->sharedQuota())
      out += "effectd_store_failures_total{store=\"quota\"} " + std::to_string(access_->quotaStoreFailures()) + "\n";
    return out;
  });
  if (access_->sharedQuota()) {  // keys on and --quota-redis (each process keeps its own buckets while it is away)
    addDegradedCheck("quotaStore", [this] {
      const std::string why = access_->quotaStoreProblem();
      return why.empty() ? why : "--quota-redis " + why + ": each replica holds keys to its own quota";
    });
  }
  metrics_.addSource([this] {
    return "# HELP effectd_memory_trims_total Times freed memory went back to the system (idle_trim.h).\n"
           "# TYPE effectd_memory_trims_total counter\n"
           "effectd_memory_trims_total " +
           std::to_string(idleTrim_->trims()) + "\n";
  });
}

Service::~Service() = default;

const Service::Route* Service::findRoute(const std::string& path) const {
  for (const auto& r : routes_)
    if (r->path == path) return r.get();
  return nullptr;
}

void Service::installCore() {
  httplib::Server& s = *http_;
  // A thread for each connection, each stream (beyond the connections: holdAsStream) and each refusal.
  const size_t threads = size_t(config_.threads),
               most = size_t(config_.maxConnections) + size_t(streams_->total()) + kRefusalThreads;
  s.new_task_queue = [threads, most] { return new ElasticPool(threads, most); };
  s.set_payload_max_length(config_.limits.maxBodyBytes);
  s.set_read_timeout(config_.readTimeoutS, 0);
  s.set_write_timeout(config_.writeTimeoutS, 0);
  s.set_keep_alive_timeout(config_.keepAliveTimeoutS);
  s.set_keep_alive_max_count(static_cast<size_t>(config_.keepAliveMaxCount));
  // cpp-httplib writes a response in two send()s (headers, then body). With Nagle's algorithm
  // on, the body waits for the ACK of the headers, and a keep-alive client delays that ACK by
  // up to 40 ms: every request after the first on a connection took ~44 ms. TCP_NODELAY is set
  // on the listening socket and Linux copies it to every accepted socket (measured: keep-alive
  // p50 44 ms -> 0.36 ms; Http.KeepAliveHasNoNagleStall guards it).
  s.set_tcp_nodelay(true);
  // cpp-httplib's default socket option is SO_REUSEPORT, which lets a second effectd bind the
  // same port and silently take half the connections. SO_REUSEADDR alone restarts cleanly over
  // TIME_WAIT and makes a port in use an error.
  s.set_socket_options([this](int sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listenSocket_ = sock;
  });

  auto addGet = [this](const std::string& path, httplib::Server::Handler h) {
    auto r = std::make_unique<Route>();
    r->path = path;
    r->methods = {"GET", "HEAD"};
    routes_.push_back(std::move(r));
    if (h) http_->Get(path, std::move(h));
  };
  // Operations: health and readiness on the public port (and the admin one), metrics on the
  // admin port when there is one, else on the public port.
  const httplib::Server::Handler healthz = [](const httplib::Request&, httplib::Response& res) {
    res.set_content("{\"status\":\"ok\"}", "application/json");
  };
  const httplib::Server::Handler readyz = [this](const httplib::Request&, httplib::Response& res) {
    answerReadiness(readiness_, degraded_, info_, res);
  };
  const httplib::Server::Handler metrics = [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(metrics_.render(), "text/plain; version=0.0.4; charset=utf-8");
  };
  addGet("/healthz", healthz);
  addGet("/readyz", readyz);
  if (config_.adminPort == 0) addGet("/metrics", metrics);
  addReadinessCheck("shutdown", [this] { return stopping_ ? std::string("shutting down") : std::string(); });
  metrics_.addSource([this] { return http_->metricsText(); });
  if (config_.adminPort != 0) {
    admin_ = std::make_unique<EdgeServer>(64);
    admin_->new_task_queue = [] { return new ElasticPool(2, 64 + kRefusalThreads); };
    admin_->set_read_timeout(config_.readTimeoutS, 0);
    admin_->set_write_timeout(config_.writeTimeoutS, 0);
    admin_->set_socket_options([](int sock) {  // as the public port's: a port in use is an error
      int yes = 1;
      ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    admin_->Get("/healthz", healthz);
    admin_->Get("/readyz", readyz);
    admin_->Get("/metrics", metrics);
  }
  addGet("/v1/openapi.yaml", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(resources().at("openapi.yaml")), "application/yaml");
  });
  // Route table entry "/v1/schemas/" stands for every schema document below it.
  addGet("/v1/schemas/", nullptr);
  http_->Get(R"(/v1/schemas/([A-Za-z0-9_.-]+))", answerSchemaDocument);
}

void Service::addJsonEndpoint(const std::string& path, const std::string& schema, JsonEndpoint endpoint) {
  schemas_->document(schema);  // fail at startup, not at the first request
  auto r = std::make_unique<Route>();
  r->path = path;
  r->methods = {"POST", "GET", "HEAD"};
  r->schema = schema;
  r->json = std::move(endpoint);
  const Route* raw = r.get();
  routes_.push_back(std::move(r));
  http_->Post(path, [this, raw](const httplib::Request& req, httplib::Response& res) { handlePost(*raw, req, res); });
  http_->Get(path, [this, raw](const httplib::Request& req, httplib::Response& res) { handleGet(*raw, req, res); });
}

void Service::addBinaryAlternative(const std::string& path, const std::string& contentType, BinaryHandler handler,
                                   BinaryEstimator cost) {
  for (auto& r : routes_)
    if (r->path == path) r->binary[contentType] = {std::move(handler), std::move(cost)};
}

void Service::addStatic(const std::string& path, const std::string& contentType, std::string body,
                        const std::string& scriptOrigin) {
  auto r = std::make_unique<Route>();
  r->path = path;
  r->methods = {"GET", "HEAD"};
  routes_.push_back(std::move(r));
  const bool html = contentType.rfind("text/html", 0) == 0;
  const std::string csp = "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'" +
                          (scriptOrigin.empty() ? "" : " " + scriptOrigin) +
                          "; connect-src 'self'; frame-ancestors 'none'";
  http_->Get(path, [contentType, html, csp, body = std::move(body)](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Content-Type-Options", "nosniff");
    if (html) res.set_header("Content-Security-Policy", csp);
    res.set_content(body, contentType);
  });
}

void Service::addReadinessCheck(const std::string& name, std::function<std::string()> probe) {
  readiness_.emplace_back(name, std::move(probe));
}

void Service::setEtagSalt(const std::string& path, std::function<std::string()> salt) {
  for (auto& r : routes_)
    if (r->path == path) r->etagSalt = std::move(salt);
}

void Service::addDegradedCheck(const std::string& name, std::function<std::string()> probe) {
  degraded_.emplace_back(name, std::move(probe));
}

void Service::addReadinessInfo(const std::string& name, std::function<std::string()> value) {
  info_.emplace_back(name, std::move(value));
}

std::string Service::reloadAccess() { return access_->reload(); }

void Service::handlePost(const Route& route, const httplib::Request& req, httplib::Response& res) {
  std::map<std::string, std::string> query;
  for (const auto& [k, v] : req.params) query[k] = v;
  const std::string type = mediaType(req.get_header_value("Content-Type"));
  // RFC 7240: a client that prefers an asynchronous answer gets a job (JSON bodies).
  if (type == "application/json" && req.get_header_value("Prefer").find("respond-async") != std::string::npos) {
    submitJob(route, req.body, res);
    return;
  }
  answer(route, req.body, type, query, req.get_header_value("If-None-Match"), res, config_);
}

void Service::handleGet(const Route& route, const httplib::Request& req, httplib::Response& res) {
  // A URL's answer is the POST's, cacheable by any cache on the way; a problem is not.
  auto refuse = [&](const ApiError& e) {
    writeProblem(res, e, tl.requestId);
    res.set_header("Cache-Control", "no-store");
  };
  // Each of r, exp and sig once, and no '=' in a value: cpp-httplib keeps the first of a repeated
  // name and cuts a value at its next '=' (base64 padding would pass silently). From the raw
  // query, as sent.
  const size_t question = req.target.find('?');
  std::map<std::string, int> given;
  for (size_t at = question == std::string::npos ? req.target.size() : question + 1; at < req.target.size();) {
    const size_t end = std::min(req.target.find('&', at), req.target.size());
    const std::string part = req.target.substr(at, end - at);
    const size_t eq = part.find('=');
    const std::string name = httplib::detail::decode_url(part.substr(0, eq), true);
    if (eq != std::string::npos && part.find('=', eq + 1) != std::string::npos)
      return refuse({400,
                     "invalid-query",
                     "Malformed query parameter",
                     name + "'s value holds '=': base64url here has no padding (RFC 4648 §5, §3.2)",
                     {{"?" + name, "holds '='"}},
                     {}});
    if (++given[name] == 2)
      return refuse({400,
                     "invalid-query",
                     "Repeated query parameter",
                     name + " is given more than once: a GET takes each of r, exp and sig once",
                     {{"?" + name, "repeated"}},
                     {}});
    at = end + 1;
  }
  for (const auto& [name, value] : req.params)
    if (name != "r" && name != "exp" && name != "sig")
      return refuse({400,
                     "invalid-query",
                     "Unknown query parameter",
                     "a GET takes r (the base64url JSON body), and exp and sig when signed; not '" + name + "'",
                     {{"?" + name, "not a parameter of GET " + route.path}},
                     {}});
  if (!req.has_param("r"))
    return refuse({400,
                   "invalid-query",
                   "Missing query parameter",
                   "GET " + route.path + " needs r: the request's JSON body in base64url (RFC 4648 §5, no padding)",
                   {{"?r", "required"}},
                   {}});
  auto body = base64UrlDecode(req.get_param_value("r"));
  if (!body)
    return refuse({400,
                   "invalid-query",
                   "Malformed query parameter",
                   "r is not base64url (RFC 4648 §5, no padding)",
                   {{"?r", "not base64url"}},
                   {}});
  if (body->size() > config_.limits.maxBodyBytes)
    return refuse({413,
                   "body-too-large",
                   "Content Too Large",
                   "r decodes to " + std::to_string(body->size()) + " bytes, over the limit of " +
                       std::to_string(config_.limits.maxBodyBytes) + " bytes (--max-body-bytes)",
                   {{"?r", "too large"}},
                   {}});
  try {
    tl.bodyTicket = admission_->admit(body->size() * kJsonBodyFactor, false);
  } catch (const ApiError& e) {
    return refuse(e);
  }
  answer(route, *body, "application/json", {}, req.get_header_value("If-None-Match"), res, config_);
  if (res.status >= 400) {
    res.set_header("Cache-Control", "no-store");
  } else if (res.has_header("ETag")) {
    // Fresh for --cache-max-age, then revalidated: the ETag names the build, so after an upgrade
    // that changes answers a cache gets the new one. A signed URL is not kept past its exp.
    long long maxAge = config_.cacheMaxAgeS;
    if (req.has_param("exp") && req.has_param("sig"))
      maxAge = std::clamp(std::atoll(req.get_param_value("exp").c_str()) - (long long)std::time(nullptr), 0LL, maxAge);
    // An answer to an API key is that key's: a shared cache that kept it would serve it to
    // requests without one. Open and signed URLs are public by design.
    res.set_header("Cache-Control", std::string(tl.key ? "private" : "public") + ", max-age=" + std::to_string(maxAge));
  } else {
    res.set_header("Cache-Control", "no-store");  // an answer with timings in it
  }
}

void Service::answer(const Route& route, const std::string& bodyText, const std::string& type,
                     const std::map<std::string, std::string>& query, const std::string& inm, httplib::Response& res,
                     const Config& config, const JobProgress& progress) {
  RequestContext ctx{tl.requestId, config, compute_.get()};
  ctx.query = query;
  ctx.progress = progress;
  // Part of what determines a binary answer; as JSON, so that no two queries read the same.
  const std::string queryText = query.empty() ? std::string() : json(query).dump();
  const Coding coding = negotiate(tl.acceptEncoding);
  tl.encoded = true;
  // The exact request bytes find a cached answer before any parsing.
  const std::string requestKey =
      bodyText.size() <= ResponseCache::kMaxAliasKeyBytes
          ? route.path + "?" + queryText + "\n" + type + "\n" + codingName(coding) + "\n" + bodyText
          : std::string();
  // A key's quota is charged the request's units: one for an answer already cached.
  auto charge = [&](size_t bytes) {
    if (!tl.key) return;
    access_->charge(*tl.key, bytes ? quotaUnits(bytes) : 1.0, res);
    tl.keyCharged = true;
  };
  try {
    if (auto hit = cache_.byRequest(requestKey)) {
      charge(0);
      res.set_header("Server-Timing", "cache;desc=\"hit\"");
      return sendAnswer(*hit, inm, res);
    }
    const auto binary = route.binary.find(type);
    const bool isBinary = binary != route.binary.end();
    json body;
    Stages requestStages;  // parse, validate, etag (and write): for Server-Timing
    if (!isBinary) parseJsonRequest(bodyText, *schemas_, route.schema, body, requestStages);
    // Deterministic answers: a strong validator per representation (request and coding), over
    // what determines the answer; none for a JSON request that asks for timings.
    std::string tag;
    if (isBinary || !asksForTimings(body)) {
      effects::Stopwatch hashing;
      tag = etagFor(route.path, route.etagSalt ? route.etagSalt() : "",
                    isBinary ? type + "\n" + queryText + "\n" + bodyText : canonicalJson(body), coding);
      requestStages.emplace_back("etag", hashing.ms());
      if (etagMatches(inm, tag)) {
        charge(0);
        res.set_header("ETag", tag);
        res.status = 304;
        return;
      }
      if (auto hit = cache_.byTag(tag)) {
        charge(0);
        cache_.alias(requestKey, tag);
        res.set_header("Server-Timing", "cache;desc=\"hit\"");
        return sendAnswer(*hit, inm, res);
      }
    }
    // The typed request and its cost; admission: the estimated peak is reserved until the
    // answer has been written; then the key's quota is charged it.
    PreparedRequest prepared;
    if (!isBinary) prepared = route.json(body, ctx);
    const Cost cost = isBinary ? binary->second.cost(bodyText, config) : prepared.cost;
    // Charged first, what X-Memory-Reserved says (the work's and the body's reservations
    // together), so that a key that cannot pay never waits for admission; a request that
    // admission then refuses (503, 413) gets its units back.
    const size_t reserved = cost.bytes + tl.bodyTicket.bytes();
    charge(reserved);
    try {
      tl.workTicket = admission_->admit(cost.bytes, cost.heavy);
    } catch (const ApiError&) {
      if (tl.key) access_->refund(*tl.key, quotaUnits(reserved));
      throw;
    }
    res.set_header("X-Memory-Reserved", std::to_string(reserved));

    auto answer = std::make_shared<CachedAnswer>();
    answer->etag = tag;
    if (isBinary)
      res.set_header("Server-Timing",
                     serverTiming(answerBinary(binary->second.handler, bodyText, ctx, *answer), {}, requestStages));
    else
      answerJson(prepared, body, *answer, res, std::move(requestStages));
    encodeAnswer(coding, *answer);
    sendAnswer(*answer, inm, res);
    if (!tag.empty()) cache_.put(std::move(answer), requestKey);
  } catch (const ApiError& e) {
    // A body that fails parsing, the schema or the endpoint's checks is not free: its size.
    if (tl.key && !tl.keyCharged && e.status >= 400 && e.status < 500 && e.status != 429)
      access_->chargeInvalid(*tl.key, bodyText.size());
    res.headers.erase("ETag");  // problems are not cacheable representations
    res.headers.erase("Server-Timing");
    tl.encoded = false;
    writeProblem(res, e, ctx.requestId);
  }
}

namespace {

// Whether the server's listen loop runs within `timeout` (polled every millisecond).
bool untilRunning(const httplib::Server& server, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!server.is_running()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace

int Service::bind() {
  const int port = config_.port == 0 ? http_->bind_to_any_port(config_.host)
                                     : (http_->bind_to_port(config_.host, config_.port) ? config_.port : -1);
  // cpp-httplib 0.11.4 listens with a backlog of 5 (compiled into Debian's .so). Clients that
  // open connections in bursts (64 wrk connections reconnecting after --keep-alive-max) then
  // overflow the accept queue, the kernel drops their SYNs, and they retry after a second:
  // wrk -c64 saw p99 1.4 s with p90 4.6 ms (nstat: TcpExtListenOverflows). Calling listen()
  // again on a listening socket sets its backlog (Linux), capped by net.core.somaxconn.
  if (port > 0 && listenSocket_ >= 0) ::listen(listenSocket_, SOMAXCONN);
  if (port > 0 && admin_) {
    if (!admin_->bind_to_port(config_.adminHost.empty() ? config_.host : config_.adminHost, config_.adminPort)) return -1;
    adminPort_ = config_.adminPort;
  }
  return port;
}

size_t Service::openConnections() const { return http_->counts().open; }

bool Service::run() {
  if (admin_) adminThread_ = std::thread([this] { admin_->listen_after_bind(); });
  const bool ok = http_->listen_after_bind();
  if (adminThread_.joinable()) {
    untilRunning(*admin_, std::chrono::milliseconds(2000));  // stop() before its loop runs would be lost
    admin_->stop();
    adminThread_.join();
  }
  return ok;
}

void Service::stop() {
  stopping_ = true;  // /readyz: not ready
  // stop() before the listen loop runs would be lost (cpp-httplib 0.11.4): wait for it.
  waitUntilRunning(std::chrono::milliseconds(2000));
  http_->drain();
  http_->stop();
}

bool Service::waitUntilRunning(std::chrono::milliseconds timeout) const { return untilRunning(*http_, timeout); }

}  // namespace effectd
