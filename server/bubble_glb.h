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

// `mesh` at the time it was built; tangent w is negated to glTF's convention (UV origin top
// left, as /v1/tangents writes it).
std::string bubbleGlb(const effects::bubble::Mesh& mesh, const effects::bubble::Params& params, const GltfFilm& film);

}  // namespace effectd
