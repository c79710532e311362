#include "service.h"

#include <httplib.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <cstdio>
#include <ctime>
#include <random>
#include <thread>

#include <malloc.h>
#include <sys/socket.h>

#include <effects/common.h>

#include "codec.h"
#include "encoding.h"
#include "json_writer.h"
#include "resources.h"

namespace effectd {

using nlohmann::json;

namespace {

constexpr size_t kMaxJsonDepth = 64;
// A JSON body costs its text, the parsed document (16-byte values in vectors that may be
// half empty: ~4x the text for arrays of short numbers), and the canonical text for the ETag.
constexpr size_t kJsonBodyFactor = 6;
constexpr size_t kBinaryBodyFactor = 2;  // the bytes and the buffers decoded from them
// After a request that reserved this much, free heap pages go back to the system at once.
constexpr size_t kTrimAfterBytes = 32u << 20;
// Headers a browser on another origin may read (CORS), and may send.
constexpr const char* kExposedHeaders =
    "ETag, Server-Timing, X-Request-ID, X-Effect-Method, X-Memory-Reserved, X-Renderer, X-Render-Passes, "
    "X-Render-Ms, X-Shader-Variants-Compiled, Retry-After";
constexpr const char* kAllowedRequestHeaders = "Content-Type, If-None-Match, X-Request-ID";

// Per-request state. A request is served start to finish on one worker thread, from the
// pre-routing handler to the logger, so thread-local storage is the request's scratch pad.
struct RequestState {
  bool active = false;
  std::chrono::steady_clock::time_point start;
  std::string route = "unmatched";
  std::string requestId;
  std::string acceptEncoding;  // taken off the request so cpp-httplib does not encode itself
  std::string corsOrigin;      // the value of Access-Control-Allow-Origin, "" = no CORS headers
  bool encoded = false;        // the answer's coding is chosen (and part of its ETag) already
  // Held until the answer has been written (the logger runs after that).
  Admission::Ticket bodyTicket, workTicket;
};
thread_local RequestState tl;

bool saneRequestId(const std::string& id) {
  if (id.empty() || id.size() > 128) return false;
  for (char c : id) {
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
              c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

std::string newRequestId() {
  thread_local std::mt19937_64 gen{std::random_device{}() ^
                                   static_cast<uint64_t>(std::hash<std::thread::id>{}(std::this_thread::get_id()))};
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(gen()));
  return buf;
}

const char* statusTitle(int status) {
  switch (status) {
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 411: return "Length Required";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 416: return "Range Not Satisfiable";
    case 422: return "Unprocessable Content";
    case 500: return "Internal Server Error";
    case 503: return "Service Unavailable";
    default: return status >= 500 ? "Server Error" : "Client Error";
  }
}

std::string mediaType(const std::string& contentType) {
  std::string t = contentType.substr(0, contentType.find(';'));
  while (!t.empty() && t.back() == ' ') t.pop_back();
  for (auto& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return t;
}

std::string jsonEscape(const std::string& s) { return json(s).dump(-1, ' ', false, json::error_handler_t::replace); }

// Parses with a nesting limit: nlohmann's parser is iterative, but a 10^5-deep document
// still costs memory and time for nothing; the contract is never deeper than a few levels.
json parseBody(const std::string& body) {
  json::parser_callback_t limit = [](int depth, json::parse_event_t, json&) {
    if (depth > static_cast<int>(kMaxJsonDepth)) throw ApiError{400, "invalid-json", "Malformed JSON",
                                                                "JSON nested deeper than 64 levels", {}, {}};
    return true;
  };
  try {
    return json::parse(body, limit, /*allow_exceptions=*/true, /*ignore_comments=*/false);
  } catch (const json::exception& e) {
    std::string what = e.what();
    // nlohmann messages look like "[json.exception.parse_error.101] parse error at line 1, ...".
    auto close = what.find("] ");
    throw ApiError{400, "invalid-json", "Malformed JSON",
                   "request body is not valid JSON: " + (close == std::string::npos ? what : what.substr(close + 2)),
                   {{"", "not valid JSON"}}, {}};
  }
}

}  // namespace

struct Service::Route {
  std::string path;
  std::vector<std::string> methods;  // GET routes also answer HEAD
  std::string schema;                // for JSON POST routes
  JsonHandler json;
  CostEstimator cost;
  struct Binary {
    BinaryHandler handler;
    BinaryEstimator cost;
  };
  std::map<std::string, Binary> binary;  // by media type
  std::function<std::string()> etagSalt;
};

ApiError toApiError(const effects::Error& error, const std::string& prefix) {
  ApiError e;
  std::string pointer = prefix + error.field;
  switch (error.kind) {
    case effects::ErrorKind::kInvalidArgument:
      e = {400, "invalid-field", "Invalid field", "", {}, {}};
      break;
    case effects::ErrorKind::kUnsatisfiable:
      e = {422, "unsatisfiable", "Request cannot be served", "", {}, {}};
      break;
    case effects::ErrorKind::kLimitExceeded:
      e = {413, "limit-exceeded", "Request exceeds a configured limit", "", {}, {}};
      break;
  }
  e.detail = (pointer.empty() ? std::string("request") : pointer) + ": " + error.message;
  e.errors.push_back({pointer, error.message});
  return e;
}

void throwError(const effects::Error& error, const std::string& prefix) { throw toApiError(error, prefix); }

void writeProblem(httplib::Response& res, const ApiError& p, const std::string& requestId) {
  json body = {{"type", "https://effectd.dev/problems/" + p.slug},
               {"title", p.title},
               {"status", p.status},
               {"detail", p.detail},
               {"requestId", requestId}};
  if (!p.errors.empty()) {
    json list = json::array();
    for (const auto& e : p.errors) list.push_back({{"pointer", e.pointer}, {"message", e.message}});
    body["errors"] = std::move(list);
  }
  res.status = p.status;
  for (const auto& [k, v] : p.headers) res.set_header(k, v);
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), "application/problem+json");
}

namespace {
Admission::Options admissionOptions(const Config& c) {
  Admission::Options o;
  o.budgetBytes = c.memoryBudgetMb ? c.memoryBudgetMb << 20
                                   : size_t(double(detectMemoryLimit().bytes) * kDefaultBudgetFraction);
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
      http_(std::make_unique<httplib::Server>()),
      compute_(std::make_unique<effects::ThreadPool>(std::max(1u, std::thread::hardware_concurrency()) - 1)) {
  std::map<std::string, std::string> docs;
  for (const auto& [name, data] : resources())
    if (name.rfind("schemas/", 0) == 0) docs[name.substr(8)] = std::string(data);
  schemas_ = std::make_unique<SchemaRegistry>(docs);
  installCore();
  installHttpPolicy();
}

Service::~Service() = default;

const Service::Route* Service::findRoute(const std::string& path) const {
  for (const auto& r : routes_)
    if (r->path == path) return r.get();
  return nullptr;
}

namespace {

// cpp-httplib serves a connection on one thread from start to end, and its read timeout is
// per read: a client trickling one header byte at a time (slowloris) holds a thread for as
// long as it likes. A fixed pool lets a handful of such clients starve everyone else, so the
// pool keeps `base` threads and grows, one thread per connection, up to `max`; only beyond
// that do connections wait. (A proxy that buffers whole requests, as deploy/nginx does, is
// the defence against attackers with more than `max` connections.)
class ElasticPool : public httplib::TaskQueue {
 public:
  ElasticPool(size_t base, size_t max) : base_(base), max_(std::max(base, max)) {
    for (size_t i = 0; i < base_; ++i) spawn();
  }
  ~ElasticPool() override { shutdown(); }
  void enqueue(std::function<void()> fn) override {
    std::unique_lock<std::mutex> lock(mu_);
    jobs_.push_back(std::move(fn));
    // Idle threads may not have woken for earlier jobs yet: count jobs, not wake-ups.
    if (jobs_.size() > idle_ && threads_.size() < max_) spawn();
    cv_.notify_one();
  }
  void shutdown() override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (stopping_) return;
      stopping_ = true;
    }
    cv_.notify_all();
    for (auto& t : threads_) t.join();
  }

 private:
  void spawn() {  // with mu_ held, or from the constructor
    threads_.emplace_back([this] { work(); });
  }
  void work() {
    std::unique_lock<std::mutex> lock(mu_);
    for (;;) {
      ++idle_;
      cv_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
      --idle_;
      if (jobs_.empty()) return;  // stopping and drained
      auto job = std::move(jobs_.front());
      jobs_.pop_front();
      lock.unlock();
      job();
      lock.lock();
    }
  }
  const size_t base_, max_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  size_t idle_ = 0;
  bool stopping_ = false;
};

}  // namespace

void Service::installCore() {
  httplib::Server& s = *http_;
  const size_t threads = size_t(config_.threads), connections = size_t(config_.maxConnections);
  s.new_task_queue = [threads, connections] { return new ElasticPool(threads, connections); };
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
  addGet("/healthz", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("{\"status\":\"ok\"}", "application/json");
  });
  addGet("/readyz", [this](const httplib::Request&, httplib::Response& res) {
    json components = json::object();
    bool ready = true;
    for (const auto& [name, probe] : readiness_) {
      std::string why = probe();
      components[name] = why.empty() ? json("ready") : json(why);
      ready = ready && why.empty();
    }
    json out = {{"status", ready ? "ready" : "not ready"}, {"components", components}};
    for (const auto& [name, value] : info_) out["info"][name] = value();
    res.status = ready ? 200 : 503;
    res.set_content(out.dump(), "application/json");
  });
  addGet("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(metrics_.render(), "text/plain; version=0.0.4; charset=utf-8");
  });
  addGet("/v1/openapi.yaml", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(resources().at("openapi.yaml")), "application/yaml");
  });
  // Route table entry "/v1/schemas/" stands for every schema document below it.
  addGet("/v1/schemas/", nullptr);
  http_->Get(R"(/v1/schemas/([A-Za-z0-9_.-]+))", [](const httplib::Request& req, httplib::Response& res) {
    auto it = resources().find("schemas/" + req.matches[1].str());
    if (it == resources().end()) {
      writeProblem(res, {404, "not-found", "Not Found", "no such schema", {}, {}}, tl.requestId);
      return;
    }
    res.set_content(std::string(it->second), "application/schema+json");
  });

  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    tl = RequestState{};
    tl.active = true;
    tl.start = std::chrono::steady_clock::now();
    metrics_.requestStarted();
    std::string given = req.get_header_value("X-Request-ID");
    tl.requestId = saneRequestId(given) ? given : newRequestId();
    res.set_header("X-Request-ID", tl.requestId);
    // effectd negotiates the coding itself (encoding.h): cpp-httplib must not see the header.
    tl.acceptEncoding = req.get_header_value("Accept-Encoding");
    const_cast<httplib::Request&>(req).headers.erase("Accept-Encoding");
    tl.corsOrigin = allowedOrigin(req.get_header_value("Origin"));

    const Route* route = findRoute(req.path);
    if (!route && req.path.rfind("/v1/schemas/", 0) == 0) route = findRoute("/v1/schemas/");
    auto fail = [&](const ApiError& p) {
      writeProblem(res, p, tl.requestId);
      return httplib::Server::HandlerResponse::Handled;
    };
    if (!route) return fail({404, "not-found", "Not Found", "no resource at " + req.path, {}, {}});
    tl.route = route->path;
    bool allowed = false;
    std::string allow;
    for (const auto& m : route->methods) {
      allowed = allowed || m == req.method;
      allow += (allow.empty() ? "" : ", ") + m;
    }
    if (req.method == "OPTIONS") {  // RFC 9110 9.3.7, and the CORS preflight
      res.status = 204;
      res.set_header("Allow", allow + ", OPTIONS");
      if (!tl.corsOrigin.empty()) {
        res.set_header("Access-Control-Allow-Methods", allow);
        res.set_header("Access-Control-Allow-Headers", kAllowedRequestHeaders);
        res.set_header("Access-Control-Max-Age", "600");
      }
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!allowed) {
      return fail({405, "method-not-allowed", "Method Not Allowed",
                   req.method + " is not allowed on " + route->path + "; allowed: " + allow, {}, {{"Allow", allow}}});
    }
    if (req.method != "POST") return httplib::Server::HandlerResponse::Unhandled;

    // Bodies must come with a Content-Length: chunked bodies bypass the payload limit in
    // cpp-httplib 0.11.4 (CVE-2025-46728), so they are refused before anything is read.
    if (req.has_header("Transfer-Encoding")) {
      return fail({411, "length-required", "Length Required",
                   "chunked request bodies are not accepted; send Content-Length", {}, {{"Connection", "close"}}});
    }
    if (!req.has_header("Content-Length")) {
      return fail({411, "length-required", "Length Required", "a POST needs a Content-Length header", {},
                   {{"Connection", "close"}}});
    }
    const std::string cl = req.get_header_value("Content-Length");
    char* end = nullptr;
    unsigned long long length = std::strtoull(cl.c_str(), &end, 10);
    if (cl.empty() || *end != '\0' || cl[0] == '-') {
      return fail({400, "bad-request", "Bad Request", "Content-Length is not a number", {}, {{"Connection", "close"}}});
    }
    if (length > config_.limits.maxBodyBytes) {
      return fail({413, "body-too-large", "Content Too Large",
                   "request body of " + cl + " bytes exceeds the limit of " +
                       std::to_string(config_.limits.maxBodyBytes) + " bytes (--max-body-bytes)",
                   {}, {{"Connection", "close"}}});
    }
    std::string type = mediaType(req.get_header_value("Content-Type"));
    bool typeOk = (type == "application/json" && route->json) || route->binary.count(type);
    if (!typeOk) {
      std::string accepted = route->json ? "application/json" : "";
      for (const auto& [t, h] : route->binary) accepted += (accepted.empty() ? "" : ", ") + t;
      return fail({415, "unsupported-media-type", "Unsupported Media Type",
                   "Content-Type '" + type + "' is not accepted here; use " + accepted, {}, {{"Accept-Post", accepted}}});
    }
    // The body is read after this handler returns: its memory is reserved before it arrives.
    try {
      tl.bodyTicket = admission_->admit(length * (type == "application/json" ? kJsonBodyFactor : kBinaryBodyFactor), false);
    } catch (const ApiError& e) {
      ApiError p = e;
      p.headers["Connection"] = "close";  // the unread body must not be taken for the next request
      return fail(p);
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });

  s.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request&, httplib::Response& res) {
    // Bodies set by a handler (problems, /readyz's 503) stand; fill in only bare statuses.
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Handled;
    if (tl.requestId.empty()) tl.requestId = newRequestId();
    std::string detail = statusTitle(res.status);
    if (res.status == 413) detail = "request body exceeds the configured limit (--max-body-bytes)";
    writeProblem(res, {res.status, res.status == 404 ? "not-found" : "http-" + std::to_string(res.status),
                       statusTitle(res.status), detail, {}, {}},
                 tl.requestId);
    return httplib::Server::HandlerResponse::Handled;
  }));

  s.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown exception";
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    std::fprintf(stderr, "{\"level\":\"error\",\"msg\":\"unhandled exception\",\"path\":%s,\"requestId\":%s,\"what\":%s}\n",
                 jsonEscape(req.path).c_str(), jsonEscape(tl.requestId).c_str(), jsonEscape(what).c_str());
    writeProblem(res, {500, "internal", "Internal Server Error", "the server failed to handle the request", {}, {}},
                 tl.requestId);
  });

  s.set_post_routing_handler([this](const httplib::Request&, httplib::Response& res) {
    if (!res.has_header("X-Request-ID")) res.set_header("X-Request-ID", tl.requestId);
    if (!tl.corsOrigin.empty()) {
      res.set_header("Access-Control-Allow-Origin", tl.corsOrigin);
      res.set_header("Access-Control-Expose-Headers", kExposedHeaders);
    }
    const std::string type = res.get_header_value("Content-Type");
    std::string vary = tl.encoded || compressible(type) ? "Accept-Encoding" : "";
    if (!config_.corsOrigins.empty() && config_.corsOrigins != std::vector<std::string>{"*"})
      vary += vary.empty() ? "Origin" : ", Origin";
    if (!vary.empty()) res.set_header("Vary", vary);
    // Answers without an ETag (contract documents, metrics, problems) are encoded here.
    if (!tl.encoded && res.body.size() >= kMinCompressBytes && compressible(type) && !res.has_header("Content-Range")) {
      Coding coding = negotiate(tl.acceptEncoding);
      if (coding != Coding::kIdentity) {
        res.body = encode(coding, res.body);
        res.set_header("Content-Encoding", codingName(coding));
        res.headers.erase("Content-Length");  // cpp-httplib set it before this handler runs
        res.set_header("Content-Length", std::to_string(res.body.size()));
      }
    }
  });

  s.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    if (!tl.active) {  // rejected before routing (e.g. unparsable request line)
      metrics_.requestStarted();
      tl.start = std::chrono::steady_clock::now();
      tl.route = "unmatched";
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tl.start).count();
    metrics_.requestFinished(tl.route, req.method.empty() ? "-" : req.method, res.status, seconds);
    if (config_.accessLog) {
      char ts[32];
      std::time_t now = std::time(nullptr);
      std::tm tm{};
      gmtime_r(&now, &tm);
      std::strftime(ts, sizeof ts, "%Y-%m-%dT%H:%M:%SZ", &tm);
      std::fprintf(stderr,
                   "{\"ts\":\"%s\",\"method\":%s,\"path\":%s,\"status\":%d,\"bytes\":%zu,\"durationMs\":%.3f,"
                   "\"requestId\":%s,\"remote\":%s}\n",
                   ts, jsonEscape(req.method).c_str(), jsonEscape(req.path).c_str(), res.status, res.body.size(),
                   seconds * 1e3, jsonEscape(tl.requestId).c_str(), jsonEscape(req.remote_addr).c_str());
    }
    const bool large = tl.bodyTicket.bytes() + tl.workTicket.bytes() >= kTrimAfterBytes;
    tl = RequestState{};  // releases the reservations: the answer has been written
    // glibc keeps freed heap pages in its per-thread arenas; after a large request, hand
    // them back now rather than holding the burst's peak for good.
    if (large) malloc_trim(0);
  });
}

std::string Service::allowedOrigin(const std::string& origin) const {
  if (origin.empty()) return "";
  for (const auto& o : config_.corsOrigins) {
    if (o == "*") return "*";
    if (o.size() == origin.size() && std::equal(o.begin(), o.end(), origin.begin(), [](char a, char b) {
          return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
        }))
      return origin;
  }
  return "";
}

void Service::installHttpPolicy() {
  addReadinessCheck("admission", [this] {
    return admission_->queueFull() ? std::string("admission queue full (--admission-queue)") : std::string();
  });
  metrics_.addSource([this] {
    const Admission::Counts a = admission_->counts();
    const ResponseCache::Counts c = cache_.counts();
    std::string out;
    auto metric = [&](const char* name, const char* type, const char* help, double value) {
      char number[32];
      std::snprintf(number, sizeof number, "%.17g", value);
      out += std::string("# HELP effectd_") + name + " " + help + "\n# TYPE effectd_" + name + " " + type + "\neffectd_" +
             name + " " + number + "\n";
    };
    metric("memory_budget_bytes", "gauge", "Bytes requests may reserve at their estimated peaks.", double(a.budgetBytes));
    metric("memory_reserved_bytes", "gauge", "Bytes reserved by requests being served.", double(a.reservedBytes));
    metric("memory_reserved_peak_bytes", "gauge", "Most bytes reserved at once since start.", double(a.peakReservedBytes));
    metric("heavy_running", "gauge", "Heavy computations running.", a.heavyRunning);
    metric("admission_waiting", "gauge", "Requests waiting for memory or a heavy slot.", a.waiting);
    metric("admission_waits_total", "counter", "Requests that had to wait before admission.", double(a.waited));
    metric("admission_refused_busy_total", "counter", "Requests refused with 503 after waiting or with the queue full.",
           double(a.refusedBusy));
    metric("admission_refused_too_large_total", "counter", "Requests refused with 413: larger than the whole budget.",
           double(a.refusedTooLarge));
    metric("response_cache_hits_total", "counter", "Answers served from the response cache.", double(c.hits));
    metric("response_cache_misses_total", "counter", "Cacheable answers that had to be computed.", double(c.misses));
    metric("response_cache_evictions_total", "counter", "Cache entries evicted to stay within --response-cache-mb.",
           double(c.evictions));
    metric("response_cache_bytes", "gauge", "Bytes held by the response cache.", double(c.bytes));
    return out;
  });
}

void Service::addJsonEndpoint(const std::string& path, const std::string& schema, JsonHandler handler,
                              CostEstimator cost) {
  schemas_->document(schema);  // fail at startup, not at the first request
  auto r = std::make_unique<Route>();
  r->path = path;
  r->methods = {"POST"};
  r->schema = schema;
  r->json = std::move(handler);
  r->cost = std::move(cost);
  const Route* raw = r.get();
  routes_.push_back(std::move(r));
  http_->Post(path, [this, raw](const httplib::Request& req, httplib::Response& res) { handlePost(*raw, req, res); });
}

void Service::addBinaryAlternative(const std::string& path, const std::string& contentType, BinaryHandler handler,
                                   BinaryEstimator cost) {
  for (auto& r : routes_)
    if (r->path == path) r->binary[contentType] = {std::move(handler), std::move(cost)};
}

void Service::addReadinessCheck(const std::string& name, std::function<std::string()> probe) {
  readiness_.emplace_back(name, std::move(probe));
}

void Service::setEtagSalt(const std::string& path, std::function<std::string()> salt) {
  for (auto& r : routes_)
    if (r->path == path) r->etagSalt = std::move(salt);
}

void Service::addReadinessInfo(const std::string& name, std::function<std::string()> value) {
  info_.emplace_back(name, std::move(value));
}

namespace {

// True when the request asks for timings in the body ("stats" in any include list): such a
// response differs from run to run and gets no ETag.
bool asksForTimings(const json& j) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      if (key == "include" && value.is_array())
        for (const auto& v : value)
          if (v == "stats") return true;
      if (asksForTimings(value)) return true;
    }
  } else if (j.is_array()) {
    for (const auto& v : j)
      if (asksForTimings(v)) return true;
  }
  return false;
}

// If-None-Match uses the weak comparison (RFC 9110 13.1.2): W/ prefixes are ignored.
bool matches(const std::string& ifNoneMatch, const std::string& etag) {
  if (ifNoneMatch.empty()) return false;
  size_t pos = 0;
  while (pos < ifNoneMatch.size()) {
    size_t end = ifNoneMatch.find(',', pos);
    if (end == std::string::npos) end = ifNoneMatch.size();
    std::string tag = ifNoneMatch.substr(pos, end - pos);
    tag.erase(0, tag.find_first_not_of(" \t"));
    tag.erase(tag.find_last_not_of(" \t") + 1);
    if (tag.rfind("W/", 0) == 0) tag.erase(0, 2);
    if (tag == "*" || tag == etag) return true;
    pos = end + 1;
  }
  return false;
}

}  // namespace

void Service::handlePost(const Route& route, const httplib::Request& req, httplib::Response& res) {
  RequestContext ctx{tl.requestId, config_, compute_.get()};
  const std::string type = mediaType(req.get_header_value("Content-Type"));
  const Coding coding = negotiate(tl.acceptEncoding);
  const std::string inm = req.get_header_value("If-None-Match");
  tl.encoded = true;
  // The exact request bytes find a cached answer before any parsing.
  const std::string requestKey = req.body.size() <= ResponseCache::kMaxAliasKeyBytes
                                     ? route.path + "\n" + type + "\n" + codingName(coding) + "\n" + req.body
                                     : std::string();
  auto send = [&](const CachedAnswer& a) {
    if (!a.etag.empty()) {  // "" = an answer with timings in it: no validator, never cached
      res.set_header("ETag", a.etag);
      if (matches(inm, a.etag)) {
        res.status = 304;
        return;
      }
    }
    for (const auto& [name, value] : a.headers) res.set_header(name, value);
    if (!a.contentEncoding.empty()) res.set_header("Content-Encoding", a.contentEncoding);
    res.set_content(a.body, a.contentType);
  };
  try {
    if (auto hit = cache_.byRequest(requestKey)) {
      res.set_header("Server-Timing", "cache;desc=\"hit\"");
      return send(*hit);
    }
    const auto binary = route.binary.find(type);
    json body;
    std::string canonical;  // what determines the answer; "" = not cacheable
    if (binary != route.binary.end()) {
      canonical = type + "\n" + req.body;
    } else {
      body = parseBody(req.body);
      auto violations = schemas_->validate(route.schema, body);
      if (!violations.empty()) {
        std::string detail = violations.front().pointer + ": " + violations.front().message;
        if (violations.size() > 1) detail += " (and " + std::to_string(violations.size() - 1) + " more)";
        throw ApiError{400, "invalid-field", "Request does not match the schema", detail, violations, {}};
      }
      if (!asksForTimings(body)) canonical = "application/json\n" + body.dump();
    }
    // Deterministic answers: a strong validator per representation (request and coding).
    std::string tag;
    if (!canonical.empty()) {
      std::string salt = route.etagSalt ? route.etagSalt() : "";
      tag = "\"" + sha256Hex(std::string(EFFECTD_VERSION) + "\n" + route.path + "\n" + salt + "\n" + canonical).substr(0, 32);
      tag += coding == Coding::kIdentity ? "\"" : std::string("-") + codingName(coding) + "\"";
      if (matches(inm, tag)) {
        res.set_header("ETag", tag);
        res.status = 304;
        return;
      }
      if (auto hit = cache_.byTag(tag)) {
        cache_.alias(requestKey, tag);
        res.set_header("Server-Timing", "cache;desc=\"hit\"");
        return send(*hit);
      }
    }
    // Admission: the estimated peak is reserved until the answer has been written.
    const Cost cost = binary != route.binary.end() ? binary->second.cost(req.body, config_) : route.cost(body, config_);
    tl.workTicket = admission_->admit(cost.bytes, cost.heavy);
    res.set_header("X-Memory-Reserved", std::to_string(cost.bytes + tl.bodyTicket.bytes()));

    auto answer = std::make_shared<CachedAnswer>();
    answer->etag = tag;
    double computeMs = 0;
    if (binary != route.binary.end()) {
      BinaryReply reply = binary->second.handler(req.body, ctx);
      computeMs = reply.computeMs;
      if (!reply.method.empty()) answer->headers["X-Effect-Method"] = reply.method;
      answer->body = std::move(reply.body);
      answer->contentType = reply.contentType;
    } else {
      JsonReply reply = route.json(body, ctx);
      body = json();  // the request document is no longer needed
      computeMs = reply.computeMs;
      if (!reply.method.empty()) answer->headers["X-Effect-Method"] = reply.method;
      answer->headers.insert(reply.headers.begin(), reply.headers.end());
      for (const auto& [name, value] : reply.runHeaders) res.set_header(name, value);
      if (!reply.contentType.empty()) {
        answer->body = std::move(reply.binary);
        answer->contentType = reply.contentType;
      } else {
        answer->body = writeJson(reply.body);
        answer->contentType = "application/json";
      }
    }
    if (coding != Coding::kIdentity && compressible(answer->contentType) && answer->body.size() >= kMinCompressBytes) {
      answer->body = encode(coding, answer->body);
      answer->contentEncoding = codingName(coding);
    }
    res.set_header("Server-Timing", "compute;dur=" + std::to_string(computeMs));
    send(*answer);
    if (!tag.empty()) cache_.put(std::move(answer), requestKey);
  } catch (const ApiError& e) {
    res.headers.erase("ETag");  // problems are not cacheable representations
    res.headers.erase("Server-Timing");
    tl.encoded = false;
    writeProblem(res, e, ctx.requestId);
  }
}

int Service::bind() {
  const int port = config_.port == 0 ? http_->bind_to_any_port(config_.host)
                                     : (http_->bind_to_port(config_.host, config_.port) ? config_.port : -1);
  // cpp-httplib 0.11.4 listens with a backlog of 5 (compiled into Debian's .so). Clients that
  // open connections in bursts (64 wrk connections reconnecting after --keep-alive-max) then
  // overflow the accept queue, the kernel drops their SYNs, and they retry after a second:
  // wrk -c64 saw p99 1.4 s with p90 4.6 ms (nstat: TcpExtListenOverflows). Calling listen()
  // again on a listening socket sets its backlog (Linux), capped by net.core.somaxconn.
  if (port > 0 && listenSocket_ >= 0) ::listen(listenSocket_, SOMAXCONN);
  return port;
}

bool Service::run() { return http_->listen_after_bind(); }

void Service::stop() {
  // stop() before the listen loop runs would be lost (cpp-httplib 0.11.4): wait for it.
  waitUntilRunning(std::chrono::milliseconds(2000));
  http_->stop();
}

bool Service::waitUntilRunning(std::chrono::milliseconds timeout) const {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!http_->is_running()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace effectd
