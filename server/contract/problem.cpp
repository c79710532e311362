#include "contract/problem.h"

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

namespace {

// The table's entry for `field` ("/name..."): its name's, else "", else none.
const FieldPlace* placeOf(const std::string& field, const FieldTable& table) {
  const size_t nameEnd = field.find('/', 1);
  const std::string name = field.substr(field.empty() ? 0 : 1, nameEnd == std::string::npos ? std::string::npos : nameEnd - 1);
  auto place = table.find(name);
  if (place == table.end() || field.empty()) place = table.find("");
  return place == table.end() ? nullptr : &place->second;
}

}  // namespace

std::string placeField(const std::string& field, const std::string& prefix, const FieldTable& table) {
  // field = "/name" then, optionally, "/element" and deeper parts.
  const FieldPlace* place = placeOf(field, table);
  if (!place) return prefix + field;
  const FieldPlace& to = *place;
  const size_t nameEnd = field.find('/', 1);
  const std::string rest = nameEnd == std::string::npos ? "" : field.substr(nameEnd);
  if (to.width == 0) return to.pointer;
  if (to.width == 1 || rest.empty()) return to.pointer + rest;
  // "/7/..." -> the element's first number on the wire: 7 * width.
  const size_t elementEnd = rest.find('/', 1);
  const std::string element = rest.substr(1, elementEnd == std::string::npos ? std::string::npos : elementEnd - 1);
  if (element.empty() || element.find_first_not_of("0123456789") != std::string::npos) return to.pointer + rest;
  return to.pointer + "/" + std::to_string(std::stoull(element) * to.width) +
         (elementEnd == std::string::npos ? "" : rest.substr(elementEnd));
}

ApiError toApiError(const effects::Error& error, const std::string& prefix, const FieldTable& table) {
  ApiError e;
  const std::string pointer = placeField(error.field, prefix, table);
  switch (error.kind) {
    case effects::ErrorKind::kInvalidArgument: e = {400, "invalid-field", "Invalid field", "", {}, {}}; break;
    case effects::ErrorKind::kUnsatisfiable: e = {422, "unsatisfiable", "Request cannot be served", "", {}, {}}; break;
    case effects::ErrorKind::kLimitExceeded:
      e = {413, "limit-exceeded", "Request exceeds a configured limit", "", {}, {}};
      break;
    case effects::ErrorKind::kCancelled: e = {409, "cancelled", "The work was cancelled", "", {}, {}}; break;
  }
  std::string message = error.message;
  if (const FieldPlace* place = placeOf(error.field, table);
      place && !place->flag.empty() && error.kind == effects::ErrorKind::kLimitExceeded)
    message += " (" + place->flag + ")";
  e.detail = (pointer.empty() ? std::string("request") : pointer) + ": " + message;
  e.errors.push_back({pointer, message});
  return e;
}

void throwError(const effects::Error& error, const std::string& prefix, const FieldTable& table) {
  throw toApiError(error, prefix, table);
}

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
