// The bolt as engine geometry: ribbons a game draws with an additive material, as JSON
// ("mesh" in /v1/lightning's answer) or as one binary glTF file (format "glb"). Both are the
// same triangles. docs/effects.md §1.8 describes the layout.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <effects/lightning.h>
#include <nlohmann/json.hpp>

#include "api/lightning_volume.h"

namespace effectd {

// One channel's ribbons (main or branches): per vertex its position (glTF axes: y up; grid
// (x, y, z) -> origin + cellSize * (x, -y, -z)), TEXCOORD_0 (u: distance along the polyline
// from its first vertex, in world units; v: 0 and 1 at the two edges), the polyline vertex's
// intensity, and with a timeline the times it lights (leader, strokeDelay).
struct Ribbons {
  bool main = false;
  std::vector<float> positions;  // x, y, z per vertex
  std::vector<float> uvs;        // u, v per vertex
  std::vector<float> intensity;
  std::vector<float> leader, strokeDelay;  // empty without a timeline
  std::vector<uint32_t> indices;           // triangles
};

// The main channel's ribbons, then the branches'. A 2-D bolt is one ribbon per polyline in the
// grid's plane (facing +z); a 3-D bolt two crossed ribbons per polyline, at right angles, their
// sides carried along each polyline without twisting (parallel transport). Each ribbon is the
// polyline's width wide (world units with `world`), mitred at the joins. `timeline` may be null.
std::array<Ribbons, 2> boltRibbons(const std::vector<effects::lightning::Polyline>& lines, int depth,
                                   const World& world, const effects::lightning::Timeline* timeline);

// "mesh": {"primitives": [{"channel", "positions", "uvs", "intensity", "indices"(, "leader",
// "strokeDelay")}, ...]}; a channel without polylines is left out.
nlohmann::json ribbonsJson(const std::array<Ribbons, 2>& ribbons);

// The ribbons as a binary glTF: nodes "main" and "branches", an unlit additive-ready material
// (baseColor = `display` (the preview's colour, sRGB-encoded; linear in the file) x an embedded
// soft-edged profile across v, COLOR_0 = intensity),
// custom attributes _LEADER and _STROKE_DELAY with a timeline, and the timeline's strokes and
// keyframes in scenes[0].extras.timeline (`timelineJson`, null without one).
std::string boltGlb(const std::array<Ribbons, 2>& ribbons, const std::array<double, 3>& display,
                    const nlohmann::json& timelineJson);

}  // namespace effectd
