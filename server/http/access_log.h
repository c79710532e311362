// One JSON line per answered request on stderr (--access-log).
#pragma once

#include <string>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace effectd {

void writeAccessLog(const httplib::Request& req, const httplib::Response& res, const std::string& requestId,
                    double seconds);
// `s` as a JSON string literal (quotes included), invalid UTF-8 replaced.
std::string jsonEscape(const std::string& s);

}  // namespace effectd
