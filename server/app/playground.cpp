#include "app/playground.h"

#include <nlohmann/json.hpp>

#include "contract/resources.h"

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

void addPlayground(Service& service, const std::string& givenThree) {
  // three.js from this origin (the built-in copy; a 404 without one, which the page reports),
  // or from --playground-three, whose origin the page's script-src then names.
  std::string threeUrl = givenThree, threeOrigin;
  if (threeUrl.empty()) {
    threeUrl = "/playground/three.module.js";
    for (const auto& [name, text] : builtInThree())
      service.addStatic("/playground/" + name, "text/javascript; charset=utf-8", std::string(text));
  } else {
    const size_t host = threeUrl.find("//") + 2, end = threeUrl.find('/', host);
    threeOrigin = threeUrl.substr(0, end);
  }
  for (const auto& [key, text] : playgroundResources()) {
    std::string name;
    if (key.rfind("server/playground/", 0) == 0) name = key.substr(std::string("server/playground/").size());
    else if (key == "clients/three/effectd-three.js") name = "effectd-three.js";
    else continue;
    std::string body(text);
    if (contentTypeOf(name).rfind("text/javascript", 0) == 0)  // the bare 'three' the page has no import map for
      for (size_t at = body.find("from 'three'"); at != std::string::npos; at = body.find("from 'three'", at))
        body.replace(at, 12, "from '" + threeUrl + "'"), at += threeUrl.size();
    service.addStatic(name == "index.html" ? "/" : "/playground/" + name, contentTypeOf(name), std::move(body),
                      threeOrigin);
  }
  service.addStatic("/playground/examples.json", "application/json", examplesIndex());
}

}  // namespace effectd
