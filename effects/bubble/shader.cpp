// GLSL for the bubble, assembled from the enabled features only: a disabled feature
// contributes no line and no uniform. Time enters as phases reduced on the CPU (reducedPhase).
// Two models (effects/bubble.h): seed 000's (eqns 3-11) and the soap film.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "effects/bubble.h"

namespace effects::bubble {
namespace {

struct Builder {
  std::ostringstream src;
  std::vector<std::string>* uniforms;
  void uniform(const std::string& type, const std::string& name, const std::string& comment, int array = 0) {
    src << "uniform " << type << " " << name;
    if (array) src << "[" << array << "]";
    src << ";  // " << comment << "\n";
    uniforms->push_back(name);
  }
  Builder& operator<<(const std::string& s) {
    src << s;
    return *this;
  }
};

std::string header(Glsl v, bool fragment) {
  if (v == Glsl::kCore330) return "#version 330 core\n";
  // Samplers default to lowp in ES fragment shaders: the thickness texture holds nanometres.
  return fragment ? "#version 300 es\nprecision highp float;\nprecision highp sampler2D;\nprecision highp samplerCube;\n"
                  : "#version 300 es\n";
}

bool film(const Features& f) { return f.shading == Shading::kFilm; }
bool usesUv(const Features& f) { return film(f) ? f.thickness : f.textureFlow; }

// The vertex shader: position (wobbled, eqn 11) with its normal carried through the wobble's
// Jacobian, world position, and the UV for the texture flow or the thickness texture.
std::string vertexShader(const Features& f, Glsl version, ShaderSource& out) {
  Builder vs{{}, &out.uniforms};
  out.attributes = {"aPosition", "aNormal"};
  vs << header(version, false) << "layout(location = 0) in vec3 aPosition;\nlayout(location = 1) in vec3 aNormal;\n";
  if (usesUv(f)) vs << "layout(location = 2) in vec2 aUv;\n", out.attributes.push_back("aUv");
  vs.uniform("mat4", "uModel", "object -> world");
  vs.uniform("mat4", "uViewProjection", "world -> clip");
  if (f.wobble) {
    vs.uniform("float", "uWobblePhase", "deltaSpeed * t mod 2 pi, reduced on the CPU (eqn 11)");
    vs.uniform("float", "uWobbleAmplitude", "object units");
    vs.uniform("float", "uWobbleFrequency", "radians per object unit");
  }
  vs << "out vec3 vNormal;\nout vec3 vWorld;\n";
  if (usesUv(f)) vs << "out vec2 vUv;\n";
  vs << "void main() {\n  vec3 p = aPosition;\n  vec3 n = aNormal;\n";
  if (f.wobble)  // eqn 11; the normal by the inverse transpose of its diagonal Jacobian
    vs << "  vec3 arg = vec3(uWobblePhase) + uWobbleFrequency * p;\n"
          "  p += uWobbleAmplitude * vec3(sin(arg.x), cos(arg.y), sin(arg.z));\n"
          "  n /= 1.0 + uWobbleAmplitude * uWobbleFrequency * vec3(cos(arg.x), -sin(arg.y), cos(arg.z));\n";
  vs << "  vec4 world = uModel * vec4(p, 1.0);\n  vWorld = world.xyz;\n"
        "  vNormal = mat3(uModel) * n;\n";
  if (usesUv(f)) vs << "  vUv = aUv;\n";
  vs << "  gl_Position = uViewProjection * world;\n}\n";
  return vs.src.str();
}

// Seed 000's fragment shader: the base colour, then each enabled feature's factor or term.
std::string paperFragment(const Features& f, Builder& fs) {
  const bool env = f.reflection || f.refraction;
  const bool needsView = env || f.rim || f.iridescence;
  fs.uniform("vec4", "uBaseColor", "colour and alpha without any feature");
  if (needsView) fs.uniform("vec3", "uCameraPosition", "world space");
  if (env) fs.uniform("samplerCube", "uEnvironment", "looked up with the final vector (eqn 8)");
  if (f.reflection) fs.uniform("float", "uFilmTop", "mu_top (eqn 3)");
  if (f.refraction) {
    fs.uniform("float", "uFilmBottom", "mu_bottom (eqn 3)");
    fs.uniform("float", "uEta", "n1 / n2 (eqn 5)");
  }
  if (f.textureFlow) {
    fs.uniform("sampler2D", "uFlowTexture", "eqn 9");
    fs.uniform("float", "uFlowPhase", "betaSpeed * t mod 2 pi, reduced on the CPU");
  }
  if (f.rim) fs.uniform("float", "uRimPower", "eqn 10");
  if (f.iridescence) {
    fs.uniform("sampler2D", "uThinFilm", "thin-film table: u = thickness, v = cos(theta)");
    fs.uniform("float", "uThickness", "film thickness as the table's u coordinate");
  }
  std::ostringstream body;
  body << "  vec4 color = uBaseColor;\n";
  if (needsView)
    body << "  vec3 N = normalize(vNormal);\n  vec3 V = normalize(uCameraPosition - vWorld);\n"
            "  float gammaOut = dot(N, V);  // eqn 4\n";
  if (env) {
    body << "  vec3 I = -V;\n  vec3 finalVector = vec3(0.0);\n";
    if (f.reflection) body << "  finalVector += (I + 2.0 * N * dot(-I, N)) * uFilmTop;  // eqns 6, 8\n";
    if (f.refraction)
      body << "  float nuIn = uEta * sqrt(max(0.0, 1.0 - gammaOut * gammaOut));  // eqn 5\n"
              "  if (nuIn < 1.0)  // otherwise total internal reflection: no refracted ray\n"
              "    finalVector += (uEta * I + (uEta * gammaOut - sqrt(1.0 - nuIn * nuIn)) * N) * uFilmBottom;  // "
              "eqn 7\n";
    body << "  color.rgb *= texture(uEnvironment, finalVector).rgb;\n";
  }
  if (f.textureFlow)
    body << "  color.rgb *= texture(uFlowTexture, vUv + vec2(sin(uFlowPhase), cos(uFlowPhase))).rgb;  // eqn 9\n";
  if (f.iridescence) body << "  color.rgb += texture(uThinFilm, vec2(uThickness, abs(gammaOut))).rgb;\n";
  if (f.rim) body << "  color.a *= clamp(pow(max(1.0 - gammaOut, 0.0), uRimPower), 0.0, 1.0);  // eqn 10\n";
  return body.str();
}

// The soap film's fragment shader: reflectance per fragment, premultiplied output.
std::string filmFragment(const Features& f, Builder& fs) {
  fs.uniform("int", "uPass",
             "0: the film's transmittance (blend ZERO, SRC_COLOR; alpha ZERO, SRC_ALPHA), then 1: its reflection "
             "(ONE, ONE); 2: both in one pass, premultiplied, transmission grey (ONE, ONE_MINUS_SRC_ALPHA)");
  fs.uniform("vec3", "uCameraPosition", "world space");
  fs.uniform("samplerCube", "uEnvironment", "what the mirror direction sees");
  fs.uniform("sampler2D", "uThinFilm", "film reflectance: u = thickness over uThicknessRange, v = cos(theta)");
  fs.uniform("vec2", "uThicknessRange", "nm at the table's first and last column");
  if (f.thickness)
    fs.uniform("sampler2D", "uThicknessField", "nm: drainage and swirl (equirectangular, REPEAT in u)");
  else
    fs.uniform("float", "uThicknessNm", "one thickness for the whole film");
  if (f.highlight) {
    fs.uniform("int", "uLightCount", "lights in use, at most " + std::to_string(kMaxLights));
    fs.uniform("vec3", "uLightDirection", "world, towards the light, unit", kMaxLights);
    fs.uniform("vec3", "uLightRadiance", "colour x intensity", kMaxLights);
    fs.uniform("float", "uLightSharpness", "lobe exponent", kMaxLights);
  }
  std::ostringstream body;
  body << "  vec3 N = normalize(vNormal);\n";
  if (f.backFace) body << "  if (!gl_FrontFacing) N = -N;  // the film seen from inside\n";
  body << "  vec3 V = normalize(uCameraPosition - vWorld);\n"
          "  float cosTheta = clamp(abs(dot(N, V)), 0.0, 1.0);\n";
  body << (f.thickness ? "  float thickness = texture(uThicknessField, vUv).r;\n"
                       : "  float thickness = uThicknessNm;\n");
  body << "  float u = clamp((thickness - uThicknessRange.x) / max(uThicknessRange.y - uThicknessRange.x, 1e-6), 0.0, "
          "1.0);\n"
          "  // the table's first and last texel centres hold the ends of its axes\n"
          "  vec2 size = vec2(textureSize(uThinFilm, 0));\n"
          "  vec2 at = (vec2(u, cosTheta) * (size - 1.0) + 0.5) / size;\n"
          "  vec3 R = texture(uThinFilm, at).rgb;  // Airy, s and p, CIE\n"
          "  vec3 r = reflect(-V, N);\n"
          "  vec3 seen = texture(uEnvironment, r).rgb;\n";
  if (f.highlight)
    body << "  for (int i = 0; i < uLightCount; ++i)\n"
            "    seen += uLightRadiance[i] * pow(max(dot(r, uLightDirection[i]), 0.0), uLightSharpness[i]);\n";
  body << "  vec4 color;\n"
          "  float opacity = dot(R, vec3(0.2126, 0.7152, 0.0722));\n"
          "  if (uPass == 0) color = vec4(1.0 - R, 1.0 - opacity);  // (ZERO, SRC_COLOR; ZERO, SRC_ALPHA): what passes\n"
          "  else if (uPass == 1) color = vec4(R * seen, opacity);  // (ONE, ONE): what the film reflects\n"
          "  else color = vec4(R * seen, opacity);  // one pass (ONE, ONE_MINUS_SRC_ALPHA), grey transmission\n";
  return body.str();
}

}  // namespace

double highlightSharpness(const Light& l) {
  const double c = std::cos(std::clamp(l.sizeDegrees, 1e-3, 89.0) * 3.14159265358979323846 / 180);
  return std::log(0.5) / std::log(c);  // c^n = 1/2
}

std::string variantKey(const Features& f) {
  std::string key = film(f) ? "film:" : "paper:";
  for (bool on : {f.reflection, f.refraction, f.rim, f.textureFlow, f.wobble, f.iridescence, f.thickness, f.backFace,
                  f.highlight})
    key += on ? '1' : '0';
  return key;
}

ShaderSource shader(const Features& f, Glsl version, const std::string& fragmentPrelude,
                    const std::string& fragmentFinish) {
  ShaderSource out;
  out.vertex = vertexShader(f, version, out);
  Builder fs{{}, &out.uniforms};
  fs << header(version, true) << "in vec3 vNormal;\nin vec3 vWorld;\n";
  if (usesUv(f)) fs << "in vec2 vUv;\n";
  fs << "out vec4 fragColor;\n";
  const std::string body = film(f) ? filmFragment(f, fs) : paperFragment(f, fs);
  fs << fragmentPrelude << "void main() {\n" << body << fragmentFinish << "  fragColor = color;\n}\n";
  out.fragment = fs.src.str();
  return out;
}

}  // namespace effects::bubble
