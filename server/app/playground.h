// The browser playground: GET / serves a page (server/playground/, embedded at build time)
// where one picks an effect, edits its request as a form generated from the JSON Schemas or as
// raw JSON, and sees the /v1/render preview, a live WebGL2 view drawn from the service's own
// answer, and the answer's method, time, error and size. It is plain HTML, CSS and ES modules;
// the live view draws through the three.js kit (clients/three/effectd-three.js), importing
// three.js from --playground-three (a CDN by default: offline, serve a copy and point it there).
#pragma once

#include "http/service.h"

namespace effectd {

// Adds / (the page), /playground/<file> (with the kit, /playground/effectd-three.js; their
// `from 'three'` imports name `threeUrl`) and /playground/examples.json: every request example
// of proto/examples/<effect>/ and the numbered scenes of examples/, grouped by effect.
void addPlayground(Service& service, const std::string& threeUrl);

}  // namespace effectd
