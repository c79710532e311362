#include "playground.h"

#include <nlohmann/json.hpp>

#include "resources.h"

namespace effectd {
namespace {

using json = nlohmann::json;

std::string contentTypeOf(const std::string& name) {
  auto ends = [&](const char* ext) {
    const std::string e(ext);
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  return "application/json";
}

// {"lightning": [{"name": "01-fast-128", "request": {...}}, ...], ..., "scene": [...]}: the
// effect examples by endpoint, then the numbered scenes of examples/ before proto's scenes.
std::string examplesIndex() {
  json index = json::object();
  auto add = [&](const std::string& effect, const std::string& file, std::string_view text) {
    std::string name = file.substr(0, file.size() - 5);  // without ".json"
    index[effect].push_back({{"name", name}, {"request", json::parse(text)}});
  };
  const std::string proto = "proto/examples/", scenes = "examples/";
  for (const auto& [key, text] : playgroundResources())
    if (key.rfind(scenes, 0) == 0) add("scene", key.substr(scenes.size()), text);
  for (const auto& [key, text] : playgroundResources()) {
    if (key.rfind(proto, 0) != 0) continue;
    const std::string rest = key.substr(proto.size());
    const size_t slash = rest.find('/');
    add(rest.substr(0, slash), rest.substr(slash + 1), text);
  }
  return index.dump();
}

}  // namespace

void addPlayground(Service& service) {
  const std::string dir = "server/playground/";
  for (const auto& [key, text] : playgroundResources()) {
    if (key.rfind(dir, 0) != 0) continue;
    const std::string name = key.substr(dir.size());
    service.addStatic(name == "index.html" ? "/" : "/playground/" + name, contentTypeOf(name), std::string(text));
  }
  service.addStatic("/playground/examples.json", "application/json", examplesIndex());
}

}  // namespace effectd
