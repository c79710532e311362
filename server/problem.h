// Problems (RFC 9457): the one error type of the HTTP layer. Endpoint code throws ApiError;
// the service writes it as application/problem+json naming the field(s) at fault.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "schema.h"

namespace effects {
struct Error;
}
namespace httplib {
struct Response;
}

namespace effectd {

// An RFC 9457 problem. Thrown by endpoint code; turned into application/problem+json.
struct ApiError {
  int status = 400;
  std::string slug;  // problem type, becomes "https://effectd.dev/problems/<slug>"
  std::string title;
  std::string detail;
  std::vector<FieldError> errors;
  std::map<std::string, std::string> headers;  // e.g. Retry-After
};

// Maps a library error to a problem: invalid argument -> 400, unsatisfiable -> 422,
// over a resource limit -> 413 (`prefix` is prepended to the field to make it a body pointer).
ApiError toApiError(const effects::Error& error, const std::string& prefix = "");
[[noreturn]] void throwError(const effects::Error& error, const std::string& prefix = "");

// Writes `p` as the response: status, its headers, the problem document with `requestId`.
void writeProblem(httplib::Response& res, const ApiError& p, const std::string& requestId);
// The reason phrase of an HTTP status (RFC 9110), for problems made from bare statuses.
const char* statusTitle(int status);

}  // namespace effectd
