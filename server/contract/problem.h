// Problems (RFC 9457): the one error type of the HTTP layer. Endpoint code throws ApiError;
// the service writes it as application/problem+json naming the field(s) at fault.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "contract/schema.h"

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

// Where an effect's parameters sit in a request. An effect names the field at fault by its own
// parameter ("/level", "/range/1", "/positions/7": the parameter, then an element); an endpoint
// places it with one table, from the parameter's name to the JSON pointer of that field, and how
// many wire numbers one of its elements takes (a vertex of flat positions: 3; 0: the element is
// not on the wire, point at the whole field). The entry "" places every name the table does not
// list; without it they go under the prefix passed down (RequestContext::at and the like).
// `flag`: the operator's flag (or field) that sets the field's limit, named in a 413's message.
struct FieldPlace {
  std::string pointer;
  size_t width = 1;
  std::string flag = "";
};
using FieldTable = std::map<std::string, FieldPlace>;
// The JSON pointer of an effect's `field` (above).
std::string placeField(const std::string& field, const std::string& prefix, const FieldTable& table = {});

// Maps a library error to a problem: invalid argument -> 400, unsatisfiable -> 422,
// over a resource limit -> 413, its field placed by placeField().
ApiError toApiError(const effects::Error& error, const std::string& prefix = "", const FieldTable& table = {});
[[noreturn]] void throwError(const effects::Error& error, const std::string& prefix = "", const FieldTable& table = {});

// Writes `p` as the response: status, its headers, the problem document with `requestId`.
void writeProblem(httplib::Response& res, const ApiError& p, const std::string& requestId);
// The reason phrase of an HTTP status (RFC 9110), for problems made from bare statuses.
const char* statusTitle(int status);

}  // namespace effectd
