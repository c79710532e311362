// POST /v1/render (a PNG of the scene) and POST /v1/scene (each effect's JSON), from the
// scene document (proto/schemas/scene.json); the scene itself is built in scene.h.
#pragma once

#include <cstddef>

#include "http/service.h"

namespace effectd {

void addRenderEndpoints(Service& service);
// The most pixels a `reference: true` render traces (400 wavelengths each).
inline constexpr size_t kMaxReferencePixels = 512 * 512;

}  // namespace effectd
