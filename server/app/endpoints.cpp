#include "app/endpoints.h"

#include "api/api_bubble.h"
#include "api/api_fog.h"
#include "api/api_lightning.h"
#include "api/api_render.h"
#include "api/api_tangents.h"

namespace effectd {

void addEffectEndpoints(Service& service) {
  addFogEndpoints(service);
  addLightningEndpoints(service);
  addTangentsEndpoints(service);
  addBubbleEndpoints(service);
  addRenderEndpoints(service);
}

}  // namespace effectd
