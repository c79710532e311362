// libFuzzer: a model/gltf-binary body through POST /v1/tangents' handler (own GLB reader,
// accessors, MikkTSpace, writer).
#include <cstdint>
#include <string>

#include "api/api_tangents.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static effectd::Config config = [] {
    effectd::Config c;
    c.limits.maxMeshVertices = 4096;
    c.limits.maxMeshTriangles = 8192;
    return c;
  }();
  try {
    effectd::RequestContext ctx{"fuzz", config};
    (void)effectd::handleGlb(std::string(reinterpret_cast<const char*>(data), size), ctx);
  } catch (const effectd::ApiError&) {
  }
  return 0;
}
