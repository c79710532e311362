// The fog in the renderer's programs: the shader text and the uniforms' values are the
// library's (effects/fog/shader.cpp, effects::fog::shader*); this uploads the values.
#include "fog.h"

namespace effects::render::detail {

void setFog(Program& p, const Fog& f, const glm::vec3& eye) {
  for (const fog::ShaderUniform& u : fog::shaderUniforms(f.global, f.regions, glm::dvec3(eye))) {
    const std::vector<float> v(u.values.begin(), u.values.end());
    const GLint at = p.at(u.name == "uFogCamera" ? u.name : u.name + "[0]");
    if (u.type.rfind("int", 0) == 0) {
      const std::vector<GLint> ints(u.values.begin(), u.values.end());
      glUniform1iv(at, GLsizei(ints.size()), ints.data());
    } else if (u.type.rfind("vec4", 0) == 0) {
      glUniform4fv(at, GLsizei(v.size() / 4), v.data());
    } else {
      glUniform3fv(at, GLsizei(v.size() / 3), v.data());
    }
  }
}

}  // namespace effects::render::detail
