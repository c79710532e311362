// POST /v1/render (a PNG of the scene) and POST /v1/scene (each effect's JSON), from the
// scene document (proto/schemas/scene.json); the scene itself is built in scene.h.
#pragma once

#include "service.h"

namespace effectd {

void addRenderEndpoints(Service& service);

}  // namespace effectd
