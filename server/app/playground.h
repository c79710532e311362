// The browser playground: GET / serves a page (server/playground/, embedded at build time)
// where one picks an effect, edits its request as a form generated from the JSON Schemas or as
// raw JSON, and sees the /v1/render preview, a live WebGL2 view drawn from the service's own
// answer, and the answer's method, time, error and size. It is plain HTML, CSS and ES modules;
// the live view draws through the three.js kit (clients/three/effectd-three.js), importing
// three.js from this server (built in, playground_three.cpp) or from --playground-three. Without
// three.js the page still works, and its live view says why it is empty.
#pragma once

#include <map>
#include <string>
#include <string_view>

#include "http/service.h"

namespace effectd {

// Adds / (the page), /playground/<file> (with the kit, /playground/effectd-three.js; their
// `from 'three'` imports name `threeUrl`, "" = the built-in copy at
// /playground/three.module.js) and /playground/examples.json: every request example of
// proto/examples/<effect>/ and the numbered scenes of examples/, grouped by effect.
void addPlayground(Service& service, const std::string& threeUrl);

// three.js's modules built into this binary by file name ("three.module.js", "three.core.js"),
// or none when the build did not find them.
std::map<std::string, std::string_view> builtInThree();

}  // namespace effectd
