// An engine's build linking the installed effect library (tests/install/install_test.sh): a
// fog table, a bolt and MikkTSpace tangents, printed as JSON for the test to compare with the
// server's answers to the same parameters.
#include <cstdio>

#include <effects/fog.h>
#include <effects/lightning.h>
#include <effects/tangents.h>
#include <effects/version.h>

static_assert(EFFECTS_VERSION_MAJOR >= 0, "effects/version.h is installed");

int main() {
  namespace fg = effects::fog;
  namespace lt = effects::lightning;
  namespace tg = effects::tangents;
  std::printf("{\"version\": \"%s\",\n", EFFECTS_VERSION_STRING);

  // {"fog": {"fogType": "GL_EXP", "density": 0.05}, "table": {"size": 64, "range": [0, 100]}}
  fg::Fog fog;
  fog.type = fg::FogType::kGlExp;
  fog.density = 0.05;
  fg::TableOptions o;
  o.size = 64;
  o.rangeStart = 0.0;
  o.rangeEnd = 100.0;
  auto table = fg::buildTable(fog, o);
  if (!table.ok()) return 1;
  std::printf("\"factor\": [");
  for (size_t i = 0; i < table.value().factor.size(); ++i) std::printf("%s%.9g", i ? ", " : "", double(table.value().factor[i]));
  std::printf("],\n");

  // {"grid": {"width": 48, "height": 48}, "start": [24, 0], "targets": [[24, 47]], "seed": 3}
  lt::Params p;
  p.width = p.height = 48;
  p.start = {24, 0};
  p.targets = {{24, 47}};
  p.seed = 3;
  lt::calibrate(p);  // as the server does
  auto bolt = lt::grow(p);
  if (!bolt.ok()) return 1;
  std::printf("\"cells\": [");
  for (size_t i = 0; i < bolt.value().nodes.size(); ++i)
    std::printf("%s%d, %d", i ? ", " : "", bolt.value().nodes[i].cell.x, bolt.value().nodes[i].cell.y);
  std::printf("],\n");

  // A quad of two triangles with a UV seam-free layout.
  tg::Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.2f}, {0, 1, 0}};
  mesh.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.indices = {0, 1, 2, 0, 2, 3};
  auto frames = tg::generate(mesh, tg::Options{});
  if (!frames.ok()) return 1;
  std::printf("\"tangents\": [");
  for (size_t i = 0; i < frames.value().tangents.size(); ++i) {
    const auto& t = frames.value().tangents[i];
    std::printf("%s%.9g, %.9g, %.9g, %.9g", i ? ", " : "", double(t.x), double(t.y), double(t.z), double(t.w));
  }
  std::printf("]}\n");
  return 0;
}
