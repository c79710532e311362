// Files of proto/ embedded into the binary at build time (cmake/embed.cmake), so the server
// serves and validates against exactly the contract it was built with, from any directory.
#pragma once

#include <map>
#include <string>
#include <string_view>

namespace effectd {
// Keys are paths relative to proto/: "openapi.yaml", "schemas/fog.json", ...
const std::map<std::string, std::string_view>& resources();
}  // namespace effectd
