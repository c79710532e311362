// GLSL ES 3.00 for the render passes. Every function returns only the code its variant
// needs (the fog's own GLSL is in fog.cpp).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "internal.h"

namespace effects::render::detail {

std::string backgroundGlsl(Background::Kind kind) {
  switch (kind) {
    case Background::Kind::kColor: return "uniform vec4 uColor;\nvec4 backgroundAt(vec2 uv) { return uColor; }\n";
    case Background::Kind::kGradient:
      return "uniform vec4 uTop;\nuniform vec4 uBottom;\n"
             "vec4 backgroundAt(vec2 uv) { return mix(uBottom, uTop, clamp(uv.y, 0.0, 1.0)); }\n";
    case Background::Kind::kImage:
      return "uniform sampler2D uImage;  // premultiplied, row 0 = top\n"
             "vec4 backgroundAt(vec2 uv) { return texture(uImage, vec2(uv.x, 1.0 - uv.y)); }\n";
  }
  return "";
}

std::string screenVertex() {
  return std::string(kVertexHeader) +
         "out vec2 vUv;\n"
         "void main() {  // one triangle over the whole target\n"
         "  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
         "  vUv = 0.5 * p + 0.5;\n"
         "  gl_Position = vec4(p, 1.0, 1.0);\n}\n";
}

std::string backgroundFragment(Background::Kind kind) {
  return std::string(kFragmentHeader) + "in vec2 vUv;\nout vec4 fragColor;\n" + backgroundGlsl(kind) +
         "void main() { fragColor = backgroundAt(vUv); }\n";
}

std::string environmentFragment(Background::Kind kind, bool sky) {
  // GL cube-map face conventions: (s, t) in [-1, 1] on the face -> direction.
  if (sky)
    return std::string(kFragmentHeader) +
           "in vec2 vUv;\nout vec4 fragColor;\n"
           "uniform int uFace;\nuniform vec3 uZenith;\nuniform vec3 uHorizon;\nuniform vec3 uGround;\n"
           "void main() {\n"
           "  float s = 2.0 * vUv.x - 1.0, t = 2.0 * vUv.y - 1.0;\n"
           "  vec3 dir = normalize(uFace == 0 ? vec3(1.0, -t, -s) : uFace == 1 ? vec3(-1.0, -t, s)\n"
           "           : uFace == 2 ? vec3(s, 1.0, t) : uFace == 3 ? vec3(s, -1.0, -t)\n"
           "           : uFace == 4 ? vec3(s, -t, 1.0) : vec3(-s, -t, -1.0));\n"
           "  vec3 c = dir.y >= 0.0 ? mix(uHorizon, uZenith, sqrt(dir.y))\n"
           "                        : mix(uHorizon, uGround, sqrt(min(-4.0 * dir.y, 1.0)));  // render::skyAt\n"
           "  fragColor = vec4(c, 1.0);\n}\n";
  return std::string(kFragmentHeader) + "in vec2 vUv;\nout vec4 fragColor;\n" + backgroundGlsl(kind) +
         "uniform int uFace;\n"
         "uniform mat3 uView;        // world -> view rotation\n"
         "uniform vec2 uTanHalfFov;  // x: horizontal, y: vertical\n"
         "void main() {\n"
         "  float s = 2.0 * vUv.x - 1.0, t = 2.0 * vUv.y - 1.0;\n"
         "  vec3 dir = uFace == 0 ? vec3(1.0, -t, -s) : uFace == 1 ? vec3(-1.0, -t, s)\n"
         "           : uFace == 2 ? vec3(s, 1.0, t) : uFace == 3 ? vec3(s, -1.0, -t)\n"
         "           : uFace == 4 ? vec3(s, -t, 1.0) : vec3(-s, -t, -1.0);\n"
         "  vec3 v = uView * normalize(dir);\n"
         "  v.z = -abs(v.z);  // behind the camera: the backdrop's mirror image\n"
         "  vec2 ndc = v.xy / max(-v.z, 1e-6) / uTanHalfFov;\n"
         "  fragColor = backgroundAt(clamp(0.5 * ndc + 0.5, 0.0, 1.0));\n"
         "}\n";
}

std::string waveVertex(bool world) {
  return std::string(kVertexHeader) +
         (world ? "layout(location = 0) in vec3 aPosition;  // world\nuniform mat4 uViewProjection;\nout vec3 vWorld;\n"
                : "layout(location = 0) in vec2 aPosition;  // NDC\n") +
         "layout(location = 1) in vec2 aUv;\n"
         "layout(location = 2) in vec3 aNormal;\n"
         "layout(location = 3) in vec4 aTangent;  // MikkTSpace, w = handedness\n"
         "out vec2 vUv;\nout vec3 vNormal;\nout vec4 vTangent;\n"
         "void main() {\n  vUv = aUv;\n  vNormal = aNormal;\n  vTangent = aTangent;\n" +
         (world ? "  vWorld = aPosition;\n  gl_Position = uViewProjection * vec4(aPosition, 1.0);\n}\n"
                : "  gl_Position = vec4(aPosition, 1.0, 1.0);\n}\n");
}

std::string waveFragment(bool world, const fog::ShaderVariant* fog) {
  std::string s = std::string(kFragmentHeader) +
                  "in vec2 vUv;\nin vec3 vNormal;\nin vec4 vTangent;\nout vec4 fragColor;\n" +
                  (world ? "in vec3 vWorld;\n" : "") +
                  "uniform sampler2D uNormalA;\nuniform sampler2D uNormalB;\nuniform sampler2D uAlpha;\n"
                  "uniform vec2 uOffsetA;  // scroll offsets, reduced modulo 1 on the CPU\n"
                  "uniform vec2 uOffsetB;\n"
                  "uniform float uScale;\nuniform float uStrength;\nuniform vec3 uLightColor;\nuniform vec3 uLight;\n";
  if (world && fog) s += fog::shaderGlsl(*fog);
  s += "void main() {\n"
       "  vec3 a = texture(uNormalA, vUv * uScale + uOffsetA).xyz * 2.0 - 1.0;\n"
       "  vec3 b = texture(uNormalB, vUv * uScale * 0.73 + uOffsetB).xyz * 2.0 - 1.0;\n"
       "  vec3 nt = normalize(vec3(a.xy + b.xy, a.z * b.z));  // the two maps combined (whiteout)\n"
       "  vec3 N = normalize(vNormal);\n"
       "  vec3 T = normalize(vTangent.xyz - N * dot(N, vTangent.xyz));\n"
       "  vec3 B = vTangent.w * cross(N, T);\n"
       "  vec3 n = normalize(mat3(T, B, N) * nt);  // seed 004: [r g b] [T; B; N]\n"
       "  float light = pow(max(dot(n, normalize(uLight)), 0.0), 24.0);\n"
       "  float alpha = texture(uAlpha, vUv * 0.5 + 0.5 * uOffsetB).r;\n"
       "  vec3 added = uLightColor * (uStrength * light * alpha);\n";
  // Light added on a fogged surface reaches the eye attenuated as the surface's own: f * added.
  if (world && fog) s += "  added = applyFog(added, vWorld) - applyFog(vec3(0.0), vWorld);\n";
  return s + "  fragColor = vec4(added, 0.0);  // added to what is behind\n}\n";
}

std::string quadVertex() {
  return std::string(kVertexHeader) +
         "layout(location = 0) in vec3 aPosition;\nlayout(location = 1) in vec3 aColor;\n"
         "uniform mat4 uViewProjection;\nout vec3 vWorld;\nout vec3 vColor;\n"
         "void main() {\n  vWorld = aPosition;\n  vColor = aColor;\n"
         "  gl_Position = uViewProjection * vec4(aPosition, 1.0);\n}\n";
}

std::string quadFragment(const fog::ShaderVariant* fog) {
  std::string s = std::string(kFragmentHeader) + "in vec3 vWorld;\nin vec3 vColor;\nout vec4 fragColor;\n";
  if (fog) s += fog::shaderGlsl(*fog);
  s += "void main() {\n  vec3 c = vColor;\n";
  if (fog) s += "  c = applyFog(c, vWorld);\n";
  return s + "  fragColor = vec4(c, 1.0);\n}\n";
}

std::string boltVertex(bool world) {
  // A 3-D bolt's vertices carry their depth (NDC z), tested against the scene's depth buffer.
  return std::string(kVertexHeader) +
         "layout(location = 0) in vec2 aPixel;\n"
         "layout(location = 1) in vec3 aLine;  // x: intensity, y: signed distance across (px), z: half width\n" +
         (world ? "layout(location = 2) in vec2 aDepth;  // x: NDC depth, y: the fog's transmittance\n" : "") +
         "uniform vec2 uSize;\nout vec3 vLine;\nout float vThrough;\n"
         "void main() {\n  vLine = aLine;\n  vThrough = " + (world ? "aDepth.y" : "1.0") + ";\n"
         "  gl_Position = vec4(2.0 * aPixel.x / uSize.x - 1.0, 1.0 - 2.0 * aPixel.y / uSize.y, " +
         (world ? "aDepth.x" : "0.0") + ", 1.0);\n}\n";
}

std::string boltFragment() {
  // Red: the light as emitted (what a glow spreads); green: as it reaches the eye through fog.
  return std::string(kFragmentHeader) +
         "in vec3 vLine;\nin float vThrough;\nout vec4 fragColor;\n"
         "void main() {  // a one-pixel anti-aliased edge\n"
         "  float cover = clamp(vLine.z + 0.5 - abs(vLine.y), 0.0, 1.0);\n"
         "  fragColor = vec4(vLine.x * cover, vLine.x * vThrough * cover, 0.0, cover);\n}\n";
}

std::string blurFragment(bool lod) {
  // Runs at half resolution: the glow is low-frequency. Samples sit on half-resolution texel
  // centres, so bilinear filtering of a full-resolution source averages 2x2 texels for free.
  // lod: the source read at mip level uLod (the APSF's wide Gaussians run at 1/2^uLod).
  const std::string fetch = lod ? "textureLod(uSource, " : "texture(uSource, ";
  const std::string lodArg = lod ? ", uLod)" : ")";
  return std::string(kFragmentHeader) +
         "uniform sampler2D uSource;\n" + (lod ? "uniform float uLod;\n" : "") +
         "uniform vec2 uStep;          // one half-resolution texel along the blur axis, in uv\n"
         "uniform vec2 uTargetSize;\n"
         "uniform int uRadius;\n"
         "uniform float uWeights[65];  // normalised Gaussian, centre first\n"
         "out vec4 fragColor;\n"
         "void main() {\n"
         "  vec2 uv = gl_FragCoord.xy / uTargetSize;\n"
         "  vec4 sum = uWeights[0] * " + fetch + "uv" + lodArg + ";\n"
         "  for (int i = 1; i <= uRadius; ++i)\n"
         "    sum += uWeights[i] * (" + fetch + "uv + float(i) * uStep" + lodArg + " + " + fetch + "uv - float(i) * uStep" +
         lodArg + ");\n"
         "  fragColor = sum;\n}\n";
}

std::string compositeFragment(bool glow, int apsf) {
  std::string s = std::string(kFragmentHeader) + "uniform sampler2D uCore;\n";
  if (glow) s += "uniform sampler2D uGlow;\nuniform float uGlowStrength;\n";
  for (int k = 0; k < apsf; ++k) s += "uniform sampler2D uApsf" + std::to_string(k) + ";\n";
  if (apsf > 0) s += "uniform float uApsfWeight[" + std::to_string(apsf) + "];\n";
  s += "uniform vec3 uColor;\nout vec4 fragColor;\n"
       "void main() {  // added over the scene\n"
       "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
       "  float light = texelFetch(uCore, p, 0).g;  // through the fog\n";
  if (glow)
    s += "  light += uGlowStrength * texture(uGlow, gl_FragCoord.xy / vec2(textureSize(uCore, 0))).r;  // upsampled\n";
  for (int k = 0; k < apsf; ++k)
    s += "  light += uApsfWeight[" + std::to_string(k) + "] * texture(uApsf" + std::to_string(k) +
         ", gl_FragCoord.xy / vec2(textureSize(uCore, 0))).r;\n";
  return s + "  fragColor = vec4(uColor * light, min(light, 1.0));\n}\n";
}

std::string blendFragment() {
  return std::string(kFragmentHeader) +
         "uniform vec3 uColor;\nuniform float uAmount;\nout vec4 fragColor;\n"
         "void main() { fragColor = vec4(uColor * uAmount, uAmount); }  // eqn 12 via blending\n";
}

std::string resolveFragment() {
  return std::string(kFragmentHeader) +
         "uniform sampler2D uFrame;\nout vec4 fragColor;\n"
         "void main() {\n"
         "  ivec2 size = textureSize(uFrame, 0);\n"
         "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
         "  vec4 c = texelFetch(uFrame, ivec2(p.x, size.y - 1 - p.y), 0);  // flipped: rows top-down\n"
         "  float a = clamp(c.a, 0.0, 1.0);\n"
         "  vec3 rgb = a > 0.0 ? clamp(c.rgb / a, 0.0, 1.0) : vec3(0.0);\n"
         "  fragColor = floor(vec4(rgb, a) * 255.0 + 0.5) / 255.0;\n"
         "}\n";
}

}  // namespace effects::render::detail
