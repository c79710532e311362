// A route of the service (internal to the service's files): its methods, and for POST its
// schema and endpoint, and per other media type a handler and cost estimator.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "http/service.h"

namespace effectd {

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
};

}  // namespace effectd
