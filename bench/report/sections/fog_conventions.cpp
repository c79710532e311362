// One height-fog scene in each engine's convention against effectd's exact integral (fog.h,
// Convention): how far apart the engines really are for the same parameters. The scene:
// density 0.05, falloff 0.2, camera at 2, start distance 5, a sun glow (exponent 8) from 10,
// 74 rays from 20 degrees down to 45 up, each at 12 distances from 1 to 2000.
#include "fog_common.h"
#include "sections.h"

namespace report {

namespace {

volatile double sink = 0;

void measure(Run& run) {
  fg::Fog base;
  base.type = fg::FogType::kHeight;
  base.density = 0.05, base.heightFalloff = 0.2, base.baseHeight = 0, base.startDistance = 5;
  fg::Directional sun;
  sun.exponent = 8.0, sun.startDistance = 10;
  base.directional = sun;
  const double cameraY = 2;
  std::vector<double> dirs, distances;
  for (int i = 0; i < 74; ++i) dirs.push_back(std::sin((-20.0 + 65.0 * i / 73.0) * kPi / 180.0));
  for (int i = 0; i < 12; ++i) distances.push_back(std::pow(2000.0, i / 11.0));
  for (fg::Convention c : {fg::Convention::kEffectd, fg::Convention::kFilament, fg::Convention::kUnreal}) {
    fg::Fog f = base;
    f.convention = c;
    double worstF = 0, worstGlow = 0;
    for (double dy : dirs)
      for (double d : distances) {
        worstF = std::max(worstF, std::abs(fg::factorAtElevation(f, cameraY, dy, d) - fg::factorAtElevation(base, cameraY, dy, d)));
        worstGlow = std::max(worstGlow, std::abs(fg::inscatterWeight(f, cameraY, dy, d) - fg::inscatterWeight(base, cameraY, dy, d)));
      }
    const size_t t = run.repeat(std::string("convention ") + fg::toString(c), run.quick ? 5 : 21, [=] {
      for (double dy : dirs)
        for (double d : distances) sink = sink + fg::factorAtElevation(f, cameraY, dy, d) + fg::inscatterWeight(f, cameraY, dy, d);
    });
    for (const auto& [quantity, error] : {std::pair{"weight f", worstF}, {"glow 1 − f_dir", worstGlow}}) {
      Row r;
      r.series = fg::toString(c);
      r.setting = quantity;
      r.request = {{"fog", {{"fogType", "HEIGHT"}, {"convention", fg::toString(c)}}}};
      r.errors["maxDifference"] = error;
      r.ticket = t;
      run.rows.push_back(r);
    }
  }
}

std::string conclude(const Section&, const Run& run) {
  std::string c = "For one scene with the same parameters:";
  for (const Row& r : run.rows)
    if (r.series != "effectd") c += " " + r.series + "'s " + r.setting + " is up to " + fmt(errorOf(r, "maxDifference")) + " from effectd's;";
  return c + " the engines' start distance and glow differ (docs/effects.md §2.4); all three cost about the same.";
}

}  // namespace

Section fogConventionsSection() {
  Section s;
  s.id = "fog-conventions";
  s.effect = "fog";
  s.title = "Height fog: each engine's convention against effectd's exact integral";
  s.reference = "effectd's convention: the exact optical depth over [startDistance, d], the glow capped like the fog";
  s.metrics = {fogMetric("maxDifference", "max abs(difference), 74 rays x 12 distances")};
  s.metrics[0].why = "as fog tables: " + s.metrics[0].why;
  s.timeName = "µs for the 888 points (median)";
  s.settingName = "quantity";
  s.timeScale = 1000;
  s.code = {"effects/fog"};
  s.measure = measure;
  s.conclude = conclude;
  return s;
}

}  // namespace report
