// A route of the service (internal to the service's files): its methods, and for POST its
// schema and endpoint, and per other media type a handler and cost estimator.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "http/service.h"

namespace effectd {

// A JSON body costs its text, the parsed document (16-byte values in vectors that may be
// half empty: ~4x the text for arrays of short numbers), and the canonical text for the ETag.
constexpr size_t kJsonBodyFactor = 6;
constexpr size_t kBinaryBodyFactor = 2;  // the bytes and the buffers decoded from them

struct Service::Route {
  std::string path;
  std::vector<std::string> methods;  // GET routes also answer HEAD
  std::string schema;                // for JSON POST routes
  JsonEndpoint json;
  struct Binary {
    BinaryHandler handler;
    BinaryEstimator cost;
  };
  std::map<std::string, Binary> binary;  // by media type
  std::function<std::string()> etagSalt;
  bool jobs = false;  // /v1/jobs and below: API keys apply (no URL signatures), JSON bodies
};

// Parses a JSON body into `body` and checks it against `schema` (400 problems), adding both
// steps' times to `stages` (service.cpp).
void parseJsonRequest(const std::string& text, const SchemaRegistry& schemas, const std::string& schema,
                      nlohmann::json& body, Stages& stages);

}  // namespace effectd
