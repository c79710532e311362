// The backdrop: a flat colour, a vertical gradient or an image, on a full-screen triangle.
#include "../gpu.h"

namespace effects::render::detail {

void setBackground(Program& p, const Background& b, const Texture* image) {
  switch (b.kind) {
    case Background::Kind::kColor: p.set("uColor", premultiplied(b.color)); break;
    case Background::Kind::kGradient:
      p.set("uTop", premultiplied(b.top));
      p.set("uBottom", premultiplied(b.bottom));
      break;
    case Background::Kind::kImage:
      image->bind(3);
      p.set("uImage", 3);
      break;
  }
}

std::optional<Error> backgroundPass(Gpu& gpu, FrameState& f) {
  const Background& bg = f.scene.background;
  auto program = gpu.program("background:" + std::to_string(int(bg.kind)),
                             [&] { return std::pair{screenVertex(), backgroundFragment(bg.kind)}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  setBackground(p, bg, &f.backgroundImage);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  f.frame.passes.push_back("background");
  return std::nullopt;
}

}  // namespace effects::render::detail
