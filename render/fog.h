// The fog in the renderer's programs: the uniforms of a program built with the library's fog
// GLSL (effects::fog::shaderGlsl of effects::fog::shaderVariant), for a camera at `eye`.
#pragma once

#include <glm/vec3.hpp>

#include "gl.h"
#include "render/render.h"

namespace effects::render::detail {

void setFog(Program& p, const Fog& f, const glm::vec3& eye);

}  // namespace effects::render::detail
