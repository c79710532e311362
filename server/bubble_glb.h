// The soap bubble as one binary glTF 2.0 file: its mesh and a material a glTF viewer draws as
// a bubble (clear, transmissive, iridescent).
#pragma once

#include <string>

#include <effects/bubble.h>

namespace effectd {

// `mesh` at the time it was built; tangent w is negated to glTF's convention (UV origin top
// left, as /v1/tangents writes it). The thin-film range is in nm. No texture is written: the
// iridescence thickness is the range's maximum everywhere (glTF's rule without a texture).
std::string bubbleGlb(const effects::bubble::Mesh& mesh, const effects::bubble::Params& params,
                      const effects::bubble::Features& features, double thicknessMinNm, double thicknessMaxNm);

}  // namespace effectd
