// The soap bubble as one binary glTF 2.0 file: its mesh and a material a glTF viewer draws as
// a bubble (clear, transmissive, iridescent).
#pragma once

#include <string>

#include <effects/bubble.h>

namespace effectd {

// The film in KHR_materials_iridescence's terms: thickness = mix(minNm, maxNm, texture.g), or
// maxNm everywhere without a texture (glTF's rule).
struct GltfFilm {
  bool iridescent = false;
  double minNm = 100, maxNm = 400;
  std::string thicknessPng;  // iridescenceThicknessTexture (rows as the mesh's v), or empty
};

// The material's base ior (KHR_materials_ior). An iridescent film is a thin shell with air on
// both sides: the base is air (1.0), and the film's own index is iridescenceIor (n2). Khronos'
// iridescence model (three.js, Babylon.js follow it) reflects at the film's back interface only
// where the base ior differs from the film's; with both at n2 the film showed colour only at the
// grazing rim. Without iridescence, n2: one interface's Fresnel reflection.
inline double baseIor(const effects::bubble::Params& p, const GltfFilm& film) { return film.iridescent ? 1.0 : p.n2; }

// `mesh` at the time it was built; tangent w is negated to glTF's convention (UV origin top
// left, as /v1/tangents writes it).
std::string bubbleGlb(const effects::bubble::Mesh& mesh, const effects::bubble::Params& params, const GltfFilm& film);

}  // namespace effectd
