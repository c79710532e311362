// A route of the service (internal to the service's files): its methods, and for POST its
// schema, handler and cost estimator, per media type.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "service.h"

namespace effectd {

struct Service::Route {
  std::string path;
  std::vector<std::string> methods;  // GET routes also answer HEAD
  std::string schema;                // for JSON POST routes
  JsonHandler json;
  CostEstimator cost;
  struct Binary {
    BinaryHandler handler;
    BinaryEstimator cost;
  };
  std::map<std::string, Binary> binary;  // by media type
  std::function<std::string()> etagSalt;
};

}  // namespace effectd
