// Pieces of the renderer that are not its public interface: EGL contexts and GLSL text.
#pragma once

#include <string>
#include <vector>

#include "fog.h"
#include "render/render.h"

namespace effects::render::detail {

// ---- EGL -------------------------------------------------------------------------------
struct EglContext {
  void* display = nullptr;
  void* context = nullptr;
  std::string platform;  // "device" or "surfaceless"
};
// Creates an OpenGL ES 3 context without any surface and makes it current on this thread.
Result<EglContext> createContext(const std::string& platform);
void destroyContext(EglContext& c);

// ---- GLSL (OpenGL ES 3.00) ---------------------------------------------------------------
inline constexpr const char* kFragmentHeader = "#version 300 es\nprecision highp float;\nprecision highp int;\n";
inline constexpr const char* kVertexHeader = "#version 300 es\n";

std::string backgroundGlsl(Background::Kind kind);  // vec4 backgroundAt(vec2 uv) (premultiplied)
std::string screenVertex();                         // full-screen triangle, no attributes
std::string backgroundFragment(Background::Kind kind);
// One cube face: direction -> the backdrop, or the sky (render::skyAt) when `sky`.
std::string environmentFragment(Background::Kind kind, bool sky);
// The surface wave over the frame (NDC positions), or on a quad in the world (`world`: world
// positions through uViewProjection, fogged as the quad when `fog`).
std::string waveVertex(bool world);
std::string waveFragment(bool world, const fog::ShaderVariant* fog);
std::string quadVertex();
std::string quadFragment(const fog::ShaderVariant* fog);
std::string boltVertex(bool world);
std::string boltFragment();
std::string blurFragment(bool lod = false);
// glow: today's Gaussian; apsf: that many Gaussians of the APSF glow (0 ... 3), uApsf0 ... 2.
std::string compositeFragment(bool glow, int apsf = 0);
std::string blendFragment();
// The frame (premultiplied, rows bottom-up) as an 8-bit PNG's rows: straight alpha, top-down,
// each value floor(255 v + 0.5) / 255 so that the RGBA8 target stores round(255 v) exactly.
std::string resolveFragment();

}  // namespace effects::render::detail
