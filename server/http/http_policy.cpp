// The service's HTTP policy, applied around every route: request ids, CORS, methods and
// OPTIONS, Content-Length and Content-Type rules, the body's memory reserved before it is
// read, problems for bare statuses and exceptions, Vary and coding of non-cached answers,
// metrics and the access log; the admission and cache gauges on /metrics.
#include <httplib.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <ctime>
#include <optional>

#include "http/access.h"
#include "http/access_log.h"
#include "http/connections.h"
#include "http/encoding.h"
#include "http/request_state.h"
#include "http/route.h"
#include "http/service.h"

namespace effectd {
namespace {

// Headers a browser on another origin may read (CORS), and may send.
// Every header a page may need to read, every X- header the service sends among them
// (tests/api_tangents_test.cpp EveryXHeaderIsExposedToAllowedOrigins).
constexpr const char* kExposedHeaders =
    "ETag, Server-Timing, Retry-After, X-Request-ID, X-Effect-Method, X-Memory-Reserved, X-Renderer, "
    "X-Render-Passes, X-Render-Ms, X-Effect-Error, X-Shader-Cache, X-Shader-Compile-Ms, X-Shader-Variants-Compiled, "
    "X-Tangents, "
    "X-Frame-Count, X-Frame-Rate, X-Flipbook-Columns, X-Flipbook-Rows, X-Content-Type-Options, RateLimit, "
    "RateLimit-Policy, WWW-Authenticate";
constexpr const char* kAllowedRequestHeaders = "Authorization, Content-Type, If-None-Match, X-Request-ID";

// The error handler: a bare status (no body from a handler) gets its problem document.
httplib::Server::HandlerResponse answerBareStatus(const httplib::Request&, httplib::Response& res) {
  // Bodies set by a handler (problems, /readyz's 503) stand; fill in only bare statuses.
  if (!res.body.empty()) return httplib::Server::HandlerResponse::Handled;
  if (tl.requestId.empty()) tl.requestId = newRequestId();
  std::string detail = statusTitle(res.status);
  std::map<std::string, std::string> headers;
  if (res.status == 413) detail = "request body exceeds the configured limit (--max-body-bytes)";
  if (res.status == 414) {  // cpp-httplib's own, before any route: the same problem as effectd's
    detail = "the URL is over 8192 bytes, the most --max-url-bytes allows: POST the body instead";
    headers["Cache-Control"] = "no-store";
  }
  writeProblem(res,
               {res.status,
                res.status == 404 ? "not-found" : res.status == 414 ? "uri-too-long" : "http-" + std::to_string(res.status),
                statusTitle(res.status),
                detail,
                {},
                headers},
               tl.requestId);
  return httplib::Server::HandlerResponse::Handled;
}

// The exception handler: logged, and answered with a 500 problem.
void answerException(const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
  std::string what = "unknown exception";
  try {
    std::rethrow_exception(ep);
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
  }
  std::fprintf(stderr,
               "{\"level\":\"error\",\"msg\":\"unhandled exception\",\"path\":%s,\"requestId\":%s,\"what\":%s}\n",
               jsonEscape(req.path).c_str(), jsonEscape(tl.requestId).c_str(), jsonEscape(what).c_str());
  writeProblem(res, {500, "internal", "Internal Server Error", "the server failed to handle the request", {}, {}},
               tl.requestId);
}

// The admission and response cache gauges and counters, in the Prometheus text format.
std::string admissionMetrics(const Admission::Counts& a, const ResponseCache::Counts& c) {
  std::string out;
  auto metric = [&](const char* name, const char* type, const char* help, double value) {
    char number[32];
    std::snprintf(number, sizeof number, "%.17g", value);
    out += std::string("# HELP effectd_") + name + " " + help + "\n# TYPE effectd_" + name + " " + type + "\neffectd_" +
           name + " " + number + "\n";
  };
  metric("memory_budget_bytes", "gauge", "Bytes requests may reserve at their estimated peaks.", double(a.budgetBytes));
  metric("memory_reserved_bytes", "gauge", "Bytes reserved by requests being served.", double(a.reservedBytes));
  metric("memory_reserved_peak_bytes", "gauge", "Most bytes reserved at once since start.",
         double(a.peakReservedBytes));
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
}

// A route's methods as an Allow header value ("GET, HEAD").
std::string allowHeader(const std::vector<std::string>& methods) {
  std::string allow;
  for (const auto& m : methods) allow += (allow.empty() ? "" : ", ") + m;
  return allow;
}

// The answer to OPTIONS (RFC 9110 9.3.7), and to the CORS preflight from an allowed origin.
void answerOptions(const std::string& allow, const std::string& corsOrigin, httplib::Response& res) {
  res.status = 204;
  res.set_header("Allow", allow + ", OPTIONS");
  if (!corsOrigin.empty()) {
    res.set_header("Access-Control-Allow-Methods", allow);
    res.set_header("Access-Control-Allow-Headers", kAllowedRequestHeaders);
    res.set_header("Access-Control-Max-Age", "600");
  }
}

// A problem that also closes the connection: the unread body must not be taken for the next request.
ApiError closing(int status, std::string slug, std::string title, std::string detail) {
  return {status, std::move(slug), std::move(title), std::move(detail), {}, {{"Connection", "close"}}};
}

// A POST's Content-Length rules, before anything of its body is read: the problem that
// refuses it, or none with `length` set.
std::optional<ApiError> lengthProblem(const httplib::Request& req, size_t maxBodyBytes, unsigned long long& length) {
  // Bodies must come with a Content-Length: chunked bodies bypass the payload limit in
  // cpp-httplib 0.11.4 (CVE-2025-46728), so they are refused before anything is read.
  if (req.has_header("Transfer-Encoding"))
    return closing(411, "length-required", "Length Required",
                   "chunked request bodies are not accepted; send Content-Length");
  if (!req.has_header("Content-Length"))
    return closing(411, "length-required", "Length Required", "a POST needs a Content-Length header");
  const std::string cl = req.get_header_value("Content-Length");
  char* end = nullptr;
  length = std::strtoull(cl.c_str(), &end, 10);
  if (cl.empty() || *end != '\0' || cl[0] == '-')
    return closing(400, "bad-request", "Bad Request", "Content-Length is not a number");
  if (length > maxBodyBytes)
    return closing(413, "body-too-large", "Content Too Large",
                   "request body of " + cl + " bytes exceeds the limit of " + std::to_string(maxBodyBytes) +
                       " bytes (--max-body-bytes)");
  return std::nullopt;
}

// The answer to a POST body of a media type the route does not take: which ones it does.
ApiError unsupportedMediaType(const std::string& type, const std::string& accepted) {
  return {415,
          "unsupported-media-type",
          "Unsupported Media Type",
          "Content-Type '" + type + "' is not accepted here; use " + accepted,
          {},
          {{"Accept-Post", accepted}}};
}

}  // namespace

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
  httplib::Server& s = *http_;
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    return preRoute(req, res) ? httplib::Server::HandlerResponse::Handled : httplib::Server::HandlerResponse::Unhandled;
  });

  s.set_error_handler(httplib::Server::HandlerWithResponse(answerBareStatus));
  s.set_exception_handler(answerException);
  s.set_post_routing_handler([this](const httplib::Request& req, httplib::Response& res) { postRoute(req, res); });

  s.set_logger([this](const httplib::Request& req, const httplib::Response& res) { finishRequest(req, res); });

  addReadinessCheck("admission", [this] {
    return admission_->queueFull() ? std::string("admission queue full (--admission-queue)") : std::string();
  });
  metrics_.addSource([this] { return admissionMetrics(admission_->counts(), cache_.counts()); });
}

// Before routing: the request's state, then every rule that can refuse it before its body is
// read. True when the response is final (a problem, an OPTIONS answer).
bool Service::preRoute(const httplib::Request& req, httplib::Response& res) {
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
  if (!route && req.path.rfind("/v1/jobs/", 0) == 0) route = findRoute("/v1/jobs/");
  auto fail = [&](const ApiError& p) {
    writeProblem(res, p, tl.requestId);
    return true;
  };
  // RFC 9110 §5.5: a field value holds no NUL, CR, LF or other control character but HTAB.
  // cpp-httplib keeps them; a key compared up to a NUL would let "<secret>\0junk" in.
  for (const auto& [name, value] : req.headers)
    if (std::any_of(value.begin(), value.end(),
                    [](unsigned char c) { return (c < 0x20 && c != '\t') || c == 0x7F; }))
      return fail({400,
                   "invalid-header",
                   "Bad Request",
                   "the " + name + " header holds a control character (RFC 9110 §5.5 allows none but HTAB)",
                   {{"header " + name, "control character"}},
                   {{"Cache-Control", "no-store"}}});
  if (!route) return fail({404, "not-found", "Not Found", "no resource at " + req.path, {}, {}});
  tl.route = route->path;
  const std::string allow = allowHeader(route->methods);
  if (req.method == "OPTIONS") {
    answerOptions(allow, tl.corsOrigin, res);
    return true;
  }
  if (std::find(route->methods.begin(), route->methods.end(), req.method) == route->methods.end()) {
    return fail({405,
                 "method-not-allowed",
                 "Method Not Allowed",
                 req.method + " is not allowed on " + route->path + "; allowed: " + allow,
                 {},
                 {{"Allow", allow}}});
  }
  // Past --max-connections (connections.h): health and readiness are answered, and an event
  // stream is checked against its client's share (429) before it is refused; nothing else is.
  const bool events = route->jobs && req.method == "GET" && req.path.size() > 7 &&
                      req.path.compare(req.path.size() - 7, 7, "/events") == 0;
  if (EdgeServer::overCapacity() && route->path != "/healthz" && route->path != "/readyz" && !events)
    return fail(EdgeServer::overCapacityProblem());
  const bool effect = route->json || !route->binary.empty();
  if (effect && req.method != "POST" && req.target.size() > config_.limits.maxUrlBytes)
    return fail({414,
                 "uri-too-long",
                 "URI Too Long",
                 "the URL has " + std::to_string(req.target.size()) + " bytes, over the limit of " +
                     std::to_string(config_.limits.maxUrlBytes) + " (--max-url-bytes): POST the body instead",
                 {},
                 {{"Cache-Control", "no-store"}}});
  if (effect || route->jobs) {
    if (auto problem = access_->check(req, route->path, (long long)std::time(nullptr), tl.key, route->jobs)) {
      if (req.method != "POST") problem->headers["Cache-Control"] = "no-store";
      if (req.method == "POST") problem->headers["Connection"] = "close";  // its body stays unread
      return fail(*problem);
    }
    if (tl.key) tl.keyId = tl.key->id;
    if (tl.key && (effect || req.method == "POST")) {  // a job's status, events and answer are free to ask
      // A key that cannot pay, or has all its places taken, is refused before its body is read.
      if (auto problem = access_->enter(*tl.key, tl.keyPlace)) {
        problem->headers[req.method == "POST" ? "Connection" : "Cache-Control"] =
            req.method == "POST" ? "close" : "no-store";
        return fail(*problem);
      }
    }
  }
  if (req.method != "POST") return false;
  unsigned long long length = 0;
  if (auto problem = lengthProblem(req, config_.limits.maxBodyBytes, length)) return fail(*problem);
  std::string type = mediaType(req.get_header_value("Content-Type"));
  bool typeOk = (type == "application/json" && (route->json || route->jobs)) || route->binary.count(type);
  if (!typeOk) {
    std::string accepted = route->json || route->jobs ? "application/json" : "";
    for (const auto& [t, h] : route->binary) accepted += (accepted.empty() ? "" : ", ") + t;
    return fail(unsupportedMediaType(type, accepted));
  }
  // The body is read after this handler returns: its memory is reserved before it arrives.
  try {
    tl.bodyTicket =
        admission_->admit(length * (type == "application/json" ? kJsonBodyFactor : kBinaryBodyFactor), false);
  } catch (const ApiError& e) {
    ApiError p = e;
    p.headers["Connection"] = "close";  // the unread body must not be taken for the next request
    return fail(p);
  }
  return false;
}

// After the handler: request id, CORS, Vary, and coding of answers that are not cached.
void Service::postRoute(const httplib::Request& req, httplib::Response& res) {
  // The connection after this answer: closed when it says so; a body left unread by a refusal
  // before it was read (415, 405, 401...) is skipped, so that it is not taken for a request.
  if (res.get_header_value("Connection") == "close") {
    EdgeServer::closeAfterThisAnswer();
  } else if (req.body.empty() && req.has_header("Content-Length")) {
    EdgeServer::skipUnreadBody(std::strtoull(req.get_header_value("Content-Length").c_str(), nullptr, 10));
  }
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
}

// After the answer has been written: metrics, the access log, the reservations released.
void Service::finishRequest(const httplib::Request& req, const httplib::Response& res) {
  if (!tl.active) {  // rejected before routing (e.g. unparsable request line)
    metrics_.requestStarted();
    tl.start = std::chrono::steady_clock::now();
    tl.route = "unmatched";
  }
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tl.start).count();
  metrics_.requestFinished(tl.route, req.method.empty() ? "-" : req.method, res.status, seconds);
  if (config_.accessLog) writeAccessLog(req, res, tl.requestId, tl.keyId, seconds);
  const bool reserved = tl.bodyTicket.bytes() + tl.workTicket.bytes() > 0;  // GETs (/metrics) reserve none
  tl = RequestState{};                      // releases the reservations: the answer has been written
  if (reserved) idleTrim_->noteFinished();  // its memory goes back once the server is idle (idle_trim.h)
}

}  // namespace effectd
