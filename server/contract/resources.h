// Files of proto/ (and of the playground) embedded into the binary at build time (cmake/embed.cmake), so the server
// serves and validates against exactly the contract it was built with, from any directory.
#pragma once

#include <map>
#include <string>
#include <string_view>

namespace effectd {
// Keys are paths relative to proto/: "openapi.yaml", "schemas/fog.json", ...
const std::map<std::string, std::string_view>& resources();
// The browser playground (server/playground/) and the request examples it starts from; keys are
// paths relative to the repository: "server/playground/index.html", "proto/examples/fog/...json",
// "examples/01-lightning.json".
const std::map<std::string, std::string_view>& playgroundResources();
// The error report's data the server states figures from (docs/error-vs-time/<section>.json);
// keys are paths relative to the repository.
const std::map<std::string, std::string_view>& reportResources();
}  // namespace effectd
