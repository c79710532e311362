// The fog in the renderer's shaders (fog.cpp): which fog types and engine terms a scene's fog
// uses, their GLSL, and the uniforms' values. Internal to render/; the public face is
// render::fogShader in render/render.h.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "gl.h"
#include "render/render.h"

namespace effects::render::detail {

// Fog: the same formulas as effects::fog::factor, per fragment, for the fog types the scene
// uses (slot 0 = global fog, slots 1..R = regions sorted by volume so that the first one
// containing a point is the one regionAt() picks). Defines vec3 applyFog(vec3 rgb, vec3 world).
struct FogVariant {
  std::vector<fog::FogType> types;  // distinct, sorted
  size_t regions = 0;
  // The engine terms some slot uses (effects/fog.h): only those are compiled in.
  bool start = false, cutoff = false, opacity = false, secondLayer = false, directional = false;
  bool filament = false, unreal = false;  // some slot follows that engine's convention
  bool engine() const { return start || cutoff || opacity || directional || filament || unreal; }
  std::string key() const;
};
FogVariant fogVariant(const Fog& fog);
std::string fogGlsl(const FogVariant& v);
// The uniforms of a program built with fogGlsl, for a camera at `eye`.
void setFog(Program& p, const Fog& f, const glm::vec3& eye);

}  // namespace effects::render::detail
