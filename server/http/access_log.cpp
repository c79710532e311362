#include "http/access_log.h"

#include <cstdio>
#include <ctime>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace effectd {

std::string jsonEscape(const std::string& s) {
  return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void writeAccessLog(const httplib::Request& req, const httplib::Response& res, const std::string& requestId,
                    const std::string& keyId, double seconds) {
  char ts[32];
  std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(ts, sizeof ts, "%Y-%m-%dT%H:%M:%SZ", &tm);
  std::fprintf(stderr,
               "{\"ts\":\"%s\",\"method\":%s,\"path\":%s,\"status\":%d,\"bytes\":%zu,\"durationMs\":%.3f,"
               "\"requestId\":%s,\"remote\":%s%s%s}\n",
               ts, jsonEscape(req.method).c_str(), jsonEscape(req.path).c_str(), res.status, res.body.size(),
               seconds * 1e3, jsonEscape(requestId).c_str(), jsonEscape(req.remote_addr).c_str(),
               keyId.empty() ? "" : ",\"key\":", keyId.empty() ? "" : jsonEscape(keyId).c_str());
}

}  // namespace effectd
