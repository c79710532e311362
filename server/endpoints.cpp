#include "endpoints.h"

#include "api_bubble.h"
#include "api_fog.h"
#include "api_lightning.h"
#include "api_render.h"
#include "api_tangents.h"

namespace effectd {

void addEffectEndpoints(Service& service) {
  addFogEndpoints(service);
  addLightningEndpoints(service);
  addTangentsEndpoints(service);
  addBubbleEndpoints(service);
  addRenderEndpoints(service);
}

}  // namespace effectd
