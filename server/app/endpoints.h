// Registration of every effect endpoint (one api_<effect>.{h,cpp} each). An endpoint file
// maps validated JSON to a library call and the result back to JSON; nothing else about
// HTTP is its business.
#pragma once

#include "http/service.h"

namespace effectd {

void addEffectEndpoints(Service& service);

}  // namespace effectd
