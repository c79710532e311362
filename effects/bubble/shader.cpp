// GLSL for seed 000's bubble, assembled from the enabled features only: a disabled feature
// contributes no line and no uniform. Time enters as phases reduced on the CPU (reducedPhase).
#include <sstream>

#include "effects/bubble.h"

namespace effects::bubble {
namespace {

struct Builder {
  std::ostringstream src;
  std::vector<std::string>* uniforms;
  void uniform(const std::string& type, const std::string& name, const std::string& comment) {
    src << "uniform " << type << " " << name << ";  // " << comment << "\n";
    uniforms->push_back(name);
  }
  Builder& operator<<(const std::string& s) {
    src << s;
    return *this;
  }
};

std::string header(Glsl v, bool fragment) {
  if (v == Glsl::kCore330) return "#version 330 core\n";
  return fragment ? "#version 300 es\nprecision highp float;\n" : "#version 300 es\n";
}

// The vertex shader: position (wobbled, eqn 11), world position, normal, and the UV for the
// texture flow. Its uniforms are appended to `uniforms`.
std::string vertexShader(const Features& f, Glsl version, std::vector<std::string>& uniforms) {
  Builder vs{{}, &uniforms};
  vs << header(version, false) << "layout(location = 0) in vec3 aPosition;\nlayout(location = 1) in vec3 aNormal;\n";
  if (f.textureFlow) vs << "layout(location = 2) in vec2 aUv;\n";
  vs.uniform("mat4", "uModel", "object -> world");
  vs.uniform("mat4", "uViewProjection", "world -> clip");
  if (f.wobble) {
    vs.uniform("float", "uWobblePhase", "deltaSpeed * t mod 2 pi, reduced on the CPU (eqn 11)");
    vs.uniform("float", "uWobbleAmplitude", "object units");
  }
  vs << "out vec3 vNormal;\nout vec3 vWorld;\n";
  if (f.textureFlow) vs << "out vec2 vUv;\n";
  vs << "void main() {\n  vec3 p = aPosition;\n";
  if (f.wobble)  // eqn 11
    vs << "  p += uWobbleAmplitude * vec3(sin(uWobblePhase + p.x), cos(uWobblePhase + p.y), sin(uWobblePhase + "
          "p.z));\n";
  vs << "  vec4 world = uModel * vec4(p, 1.0);\n  vWorld = world.xyz;\n"
        "  vNormal = mat3(uModel) * aNormal;\n";
  if (f.textureFlow) vs << "  vUv = aUv;\n";
  vs << "  gl_Position = uViewProjection * world;\n}\n";
  return vs.src.str();
}

// The fragment shader: the base colour, then each enabled feature's factor or term in turn,
// with the caller's prelude (declarations) and finish (before the output). Its uniforms are
// appended to `uniforms`.
std::string fragmentShader(const Features& f, Glsl version, const std::string& fragmentPrelude,
                           const std::string& fragmentFinish, std::vector<std::string>& uniforms) {
  const bool env = f.reflection || f.refraction;
  const bool needsView = env || f.rim || f.iridescence;
  Builder fs{{}, &uniforms};
  fs << header(version, true) << "in vec3 vNormal;\nin vec3 vWorld;\n";
  if (f.textureFlow) fs << "in vec2 vUv;\n";
  fs << "out vec4 fragColor;\n";
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
  fs << fragmentPrelude << "void main() {\n  vec4 color = uBaseColor;\n";
  if (needsView)
    fs << "  vec3 N = normalize(vNormal);\n  vec3 V = normalize(uCameraPosition - vWorld);\n"
          "  float gammaOut = dot(N, V);  // eqn 4\n";
  if (env) {
    fs << "  vec3 I = -V;\n  vec3 finalVector = vec3(0.0);\n";
    if (f.reflection) fs << "  finalVector += (I + 2.0 * N * dot(-I, N)) * uFilmTop;  // eqns 6, 8\n";
    if (f.refraction)
      fs << "  float nuIn = uEta * sqrt(max(0.0, 1.0 - gammaOut * gammaOut));  // eqn 5\n"
            "  if (nuIn < 1.0)  // otherwise total internal reflection: no refracted ray\n"
            "    finalVector += (uEta * I + (uEta * gammaOut - sqrt(1.0 - nuIn * nuIn)) * N) * uFilmBottom;  // eqn "
            "7\n";
    fs << "  color.rgb *= texture(uEnvironment, finalVector).rgb;\n";
  }
  if (f.textureFlow)
    fs << "  color.rgb *= texture(uFlowTexture, vUv + vec2(sin(uFlowPhase), cos(uFlowPhase))).rgb;  // eqn 9\n";
  if (f.iridescence) fs << "  color.rgb += texture(uThinFilm, vec2(uThickness, abs(gammaOut))).rgb;\n";
  if (f.rim) fs << "  color.a *= clamp(pow(max(1.0 - gammaOut, 0.0), uRimPower), 0.0, 1.0);  // eqn 10\n";
  fs << fragmentFinish << "  fragColor = color;\n}\n";
  return fs.src.str();
}

}  // namespace

ShaderSource shader(const Features& f, Glsl version, const std::string& fragmentPrelude,
                    const std::string& fragmentFinish) {
  ShaderSource out;
  out.vertex = vertexShader(f, version, out.uniforms);
  out.fragment = fragmentShader(f, version, fragmentPrelude, fragmentFinish, out.uniforms);
  return out;
}

}  // namespace effects::bubble
