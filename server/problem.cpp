#include "problem.h"

#include <httplib.h>

#include <effects/common.h>

namespace effectd {

using nlohmann::json;

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

ApiError toApiError(const effects::Error& error, const std::string& prefix) {
  ApiError e;
  std::string pointer = prefix + error.field;
  switch (error.kind) {
    case effects::ErrorKind::kInvalidArgument: e = {400, "invalid-field", "Invalid field", "", {}, {}}; break;
    case effects::ErrorKind::kUnsatisfiable: e = {422, "unsatisfiable", "Request cannot be served", "", {}, {}}; break;
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
  json list = json::array();  // always present: one shape for every problem
  for (const auto& e : p.errors) list.push_back({{"pointer", e.pointer}, {"message", e.message}});
  body["errors"] = std::move(list);
  res.status = p.status;
  for (const auto& [k, v] : p.headers) res.set_header(k, v);
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), "application/problem+json");
}

}  // namespace effectd
