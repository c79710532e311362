// Tangent frames for normal mapping: the cheaper modes against MikkTSpace, on a smooth UV
// sphere and a mirrored bumpy torus (100k triangles' worth of time).
#include <effects/tangents.h>

#include "fixtures.h"
#include "sections.h"

namespace report {

namespace {

namespace tg = effects::tangents;

void measure(Run& run) {
  struct M {
    std::string name;
    tg::Mesh mesh;
  };
  const int rings = run.quick ? 40 : 200, segments = run.quick ? 50 : 250;
  const std::vector<M> meshes = {{"UV sphere", fixtures::uvSphere(rings, segments)},
                                 {"mirrored bumpy torus", fixtures::mirroredTorus(rings, segments)}};
  for (const M& m : meshes) {
    const double per100k = 100000.0 / double(m.mesh.indices.size() / 3);
    for (tg::Mode mode : {tg::Mode::kMikkTSpace, tg::Mode::kPerVertex, tg::Mode::kPerTriangle}) {
      tg::Options o;
      o.mode = mode;
      Row r;
      r.series = tg::toString(mode);
      r.setting = m.name;
      r.group = m.name;
      r.request = {{"mode", tg::toString(mode)}};
      r.timeFactor = per100k;
      r.ticket = run.repeat(m.name + " " + tg::toString(mode), run.quick ? 5 : 9, [mesh = m.mesh, o] { (void)tg::generate(mesh, o); });
      r.errors["meanAngleDeg"] = 0;
      r.note = "—";
      if (mode != tg::Mode::kMikkTSpace) {
        o.measureError = true;
        auto g = tg::generate(m.mesh, o);
        const auto& st = g.value().stats;
        r.errors["meanAngleDeg"] = st.error.value_or(NAN);
        r.note = fmt(st.counters.at("maxAngleDeg"), 3) + "°, " + fmt(st.counters.at("handednessMismatches"), 6);
      }
      run.rows.push_back(r);
    }
  }
}

std::string conclude(const Section&, const Run& run) {
  const std::string sphere = run.rows.front().setting;
  const Row *mikk = nullptr, *vert = nullptr, *tri = nullptr;
  for (const Row& r : run.rows) {
    if (r.setting != sphere) continue;
    if (r.series == "mikktspace") mikk = &r;
    if (r.series == "perVertex") vert = &r;
    if (r.series == "perTriangle") tri = &r;
  }
  if (!mikk || !vert || !tri) return "";
  std::string c = "On the smooth sphere perVertex ";
  if (tie(*mikk, *vert))
    c += "ties with MikkTSpace in time (their interquartile ranges overlap: " + fmt(vert->ms) + " and " + fmt(mikk->ms) + " ms)";
  else
    c += "is " + fmt(mikk->ms / std::max(vert->ms, 1e-9), 2) + "× as fast as MikkTSpace";
  return c + " at a mean " + fmt(errorOf(*vert, "meanAngleDeg"), 2) + "° (perTriangle " + fmt(errorOf(*tri, "meanAngleDeg"), 2) +
         "°); normal maps are baked in MikkTSpace, any mismatch shows as seams, and mirrored UVs break the averaged "
         "frames (see the torus): MikkTSpace is the default.";
}

}  // namespace

Section tangentsSection() {
  Section s;
  s.id = "tangents";
  s.effect = "tangents";
  s.title = "Bump mapping: tangent frames against MikkTSpace";
  s.reference = "MikkTSpace (effectd's implementation, checked against the npm mikktspace WASM build in the tests)";
  s.metrics = {{"meanAngleDeg", "angle", "mean angle between corner tangents, degrees", 5.0,
                "a mean 5 degree tilt shows in normal-mapped highlights"}};
  s.timeName = "ms per 100k triangles (median)";
  s.settingName = "mesh";
  s.noteName = "max angle, handedness mismatches";
  s.code = {"effects/tangents"};
  s.asks = {{"UV sphere", "tangents for 100k triangles of a smooth mesh"},
            {"mirrored bumpy torus", "tangents for 100k triangles with mirrored UVs"}};
  s.measure = measure;
  s.conclude = conclude;
  return s;
}

}  // namespace report
