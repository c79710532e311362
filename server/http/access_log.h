// One JSON line per answered request on stderr (--access-log): never a secret (no query
// string, no Authorization), the API key's id when the request came with one.
#pragma once

#include <string>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace effectd {

void writeAccessLog(const httplib::Request& req, const httplib::Response& res, const std::string& requestId,
                    const std::string& keyId, double seconds);
// `s` as a JSON string literal (quotes included), invalid UTF-8 replaced.
std::string jsonEscape(const std::string& s);

}  // namespace effectd
