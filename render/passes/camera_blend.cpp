// Seed 000 eqn 12: the whole frame blended toward a colour (a flash, a fade).
#include "../gpu.h"

namespace effects::render::detail {

std::optional<Error> cameraBlendPass(Gpu& gpu, FrameState& f) {
  auto program = gpu.program("cameraBlend", [] { return std::pair{screenVertex(), blendFragment()}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  p.set("uColor", glm::vec3(f.scene.blend->color));
  p.set("uAmount", float(f.scene.blend->amount));
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDisable(GL_BLEND);
  f.frame.passes.push_back("cameraBlend");
  return std::nullopt;
}

}  // namespace effects::render::detail
