// libFuzzer: a JSON request body through the real path — parse (server/contract/json_reader.h, checked
// against nlohmann's parser on every input it accepts), schema
// validation, the endpoint's handler — for every JSON endpoint. The first byte picks the
// endpoint. Limits are small so that valid inputs stay fast; ApiError is the expected way out.
#include <cmath>
#include <cstdint>
#include <string>

#include "api/api_bubble.h"
#include "api/api_fog.h"
#include "api/api_lightning.h"
#include "api/api_tangents.h"
#include "contract/json_reader.h"
#include "api/api_render.h"
#include "api/scene.h"
#include "http/service.h"

namespace {

using effectd::JsonReply;
using effectd::RequestContext;
using nlohmann::json;

effectd::Config fuzzConfig() {
  effectd::Config c;
  c.limits.maxGridCells = 64 * 64;
  c.limits.maxGrowthSteps = 20000;
  c.limits.maxTableSize = 4096;
  c.limits.maxMeshVertices = 4096;
  c.limits.maxMeshTriangles = 8192;
  c.limits.maxRenderPixels = 64 * 64;
  c.limits.maxThinFilmTexels = 64 * 64;
  return c;
}

struct Endpoint {
  const char* schema;
  JsonReply (*handle)(const json&, const RequestContext&);
};

JsonReply buildOnly(const json& body, const RequestContext& ctx) {  // no GL in a fuzzer
  (void)effectd::buildScene(effectd::parseRenderRequest(body, ctx), body, ctx);
  return {};
}

const Endpoint kEndpoints[] = {{"fog.json", effectd::handleFog},
                               {"lightning.json", effectd::handleLightning},
                               {"tangents.json", effectd::handleTangents},
                               {"bubble.json", effectd::handleBubble},
                               {"scene.json", buildOnly}};

// Equal with the same value types throughout (operator== takes 1, 1u and 1.0 for one another).
bool identical(const json& a, const json& b) {
  if (a.type() != b.type() || a.size() != b.size()) return false;
  if (a.is_object()) {
    for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j)
      if (i.key() != j.key() || !identical(*i, *j)) return false;
    return true;
  }
  if (a.is_array()) {
    for (size_t i = 0; i < a.size(); ++i)
      if (!identical(a[i], b[i])) return false;
    return true;
  }
  return a.is_number_float() ? std::signbit(a.get<double>()) == std::signbit(b.get<double>()) && a == b : a == b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const effectd::Config config = fuzzConfig();
  static effectd::Service service(config);  // its schema registry; it never listens
  if (size < 1) return 0;
  const Endpoint& e = kEndpoints[data[0] % (sizeof kEndpoints / sizeof kEndpoints[0])];
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  json body;
  try {
    body = effectd::readJson(text);
  } catch (const effectd::JsonSyntaxError&) {
    return 0;
  }
  // What the reader accepts, nlohmann's parser accepts as the same document.
  const json reference = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (reference.is_discarded() || !identical(reference, body)) __builtin_trap();
  if (!service.schemas().validate(e.schema, body).empty()) return 0;
  try {
    RequestContext ctx{"fuzz", config};
    JsonReply r = e.handle(body, ctx);
    (void)r.body.dump(-1, ' ', false, json::error_handler_t::replace);
  } catch (const effectd::ApiError&) {
  }
  return 0;
}
