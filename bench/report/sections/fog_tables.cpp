// Fog colour tables of every size, per fog type and engine term, against the exact function.
#include "fog_common.h"
#include "sections.h"

namespace report {

namespace {

volatile double sink = 0;

struct Series {
  fg::Fog fog;
  std::string name;
  fg::TableOptions::Layout layout = fg::TableOptions::Layout::kLinear;
  double cameraHeight = 5;

};

std::vector<Series> allSeries() {
  using Layout = fg::TableOptions::Layout;
  std::vector<Series> out;
  for (fg::FogType t : {fg::FogType::kX3dLinear, fg::FogType::kX3dExponential, fg::FogType::kGlLinear,
                        fg::FogType::kGlExp, fg::FogType::kGlExp2, fg::FogType::kDistanceExp2,
                        fg::FogType::kDistanceGaussian, fg::FogType::kHeight, fg::FogType::kAtmospheric})
    out.push_back({reportFog(t), fg::toString(t)});
  // The engine terms (fog.h): a start distance, an opacity cap, a cutoff, height fog's second
  // layer and the sun's glow, whose weight 1 - f_dir is a second channel of the same table
  // (the error is the worse of the two channels).
  for (fg::FogType t : {fg::FogType::kGlExp, fg::FogType::kHeight}) {
    fg::Fog f = reportFog(t);
    f.startDistance = 5;
    f.maxOpacity = 0.95;
    if (t == fg::FogType::kHeight)
      f.secondLayer = fg::HeightLayer{0.01, 0.05, 3};
    else
      f.cutoffDistance = 120;
    fg::Directional sun;
    sun.startDistance = 12;
    f.directional = sun;
    out.push_back({f, std::string(fg::toString(t)) + " + engine terms"});
    if (t == fg::FogType::kHeight) {
      out.push_back({reportFog(t), "HEIGHT warped", Layout::kWarped});
      out.push_back({f, "HEIGHT + engine terms warped", Layout::kWarped});
    }
  }
  // Example 08's sunset (examples/08-sunset-fog.json, camera at 1.7): two layers, a start, a
  // cap and a glow from 10 m, in both layouts.
  fg::Fog sunset = reportFog(fg::FogType::kHeight);
  sunset.color = {0.42, 0.36, 0.42};
  sunset.density = 0.012;
  sunset.heightFalloff = 0.06;
  sunset.baseHeight = 0;
  sunset.startDistance = 3;
  sunset.maxOpacity = 0.97;
  sunset.secondLayer = fg::HeightLayer{0.05, 0.9, 0};
  fg::Directional glow;
  glow.color = {0.2, 0.1, 0.04};
  glow.direction = {0.02, 0.06, -1};
  glow.g = 0.55;
  glow.startDistance = 10;
  sunset.directional = glow;
  out.push_back({sunset, "HEIGHT sunset (example 08)", Layout::kLinear, 1.7});
  out.push_back({sunset, "HEIGHT sunset (example 08) warped", Layout::kWarped, 1.7});
  return out;
}

// A warped series joins its linear twin's group: the summary picks between layouts.
std::string groupOf(const std::string& name) {
  const size_t w = name.rfind(" warped");
  return w == std::string::npos ? name : name.substr(0, w);
}

void measure(Run& run) {
  using Layout = fg::TableOptions::Layout;
  const std::vector<size_t> sizes =
      run.quick ? std::vector<size_t>{16, 64, 256} : std::vector<size_t>{16, 32, 64, 128, 256, 512, 1024, 2048, 4096};
  for (const Series& s : allSeries()) {
    const bool twoD = s.fog.type == fg::FogType::kHeight;
    for (size_t n : sizes) {  // height fog's tables are 2-D: n x n linear or n x n/2 warped, up to 65 536 entries
      fg::TableOptions o;
      o.size = n;
      o.layout = s.layout;
      o.elevations = twoD ? fg::tableRows(o, n) : 0;
      if (twoD && n * o.elevations > o.maxSize) continue;
      o.cameraHeight = s.cameraHeight;
      o.measureError = false;
      Row r;
      r.series = s.name;
      r.setting = std::to_string(n) + (twoD ? " × " + std::to_string(o.elevations) : "");
      r.group = groupOf(s.name);
      r.request = {{"table", {{"size", n}}}};
      if (twoD) {
        r.request["table"]["elevations"] = o.elevations;
        r.request["table"]["layout"] = s.layout == Layout::kWarped ? "warped" : "linear";
      }
      r.ticket = run.repeat(s.name + " " + std::to_string(n), run.quick ? 5 : 21, [f = s.fog, o] { (void)fg::buildTable(f, o); });
      o.measureError = true;  // the same table, measured
      auto table = fg::buildTable(s.fog, o);
      r.errors["maxError"] = table.ok() ? table.value().maxError : NAN;
      run.rows.push_back(r);
    }
  }
}

std::string conclude(const Section&, const Run& run) {
  std::string c = "Smallest table meeting 8-bit precision (max error ≤ 1/255) per type:";
  std::map<std::string, const Row*> best;
  std::map<std::string, std::string> largest;
  for (const Row& r : run.rows) {
    largest[r.series] = r.setting;
    if (errorOf(r, "maxError") <= 1.0 / 255 && (!best[r.series] || r.ms < best[r.series]->ms)) best[r.series] = &r;
    best.emplace(r.series, nullptr);
  }
  for (const auto& [series, r] : best)
    c += r ? " " + series + " " + r->setting + " (" + fmt(r->ms * 1000) + " µs);" : " " + series + " none up to " + largest[series] + ";";
  const Row *slowest = nullptr, *quickest = fastestWithin(run, "maxError", 1.0);
  for (const Row& r : run.rows)
    if (!slowest || r.ms > slowest->ms) slowest = &r;
  if (slowest && quickest)
    c += " a table costs " + fmt(quickest->ms * 1000) + " µs (" + quickest->series + " " + quickest->setting + ") to " +
         fmt(slowest->ms * 1000) + " µs (" + slowest->series + " " + slowest->setting +
         "); below a millisecond, size a table by its error bound, not by its time.";
  return c;
}

}  // namespace

Section fogTablesSection() {
  Section s;
  s.id = "fog-tables";
  s.effect = "fog";
  s.title = "Fog: colour tables against the exact function";
  s.reference = "the exact closed form, sampled 16x between table entries";
  s.metrics = {fogMetric("maxError", "max abs(lerp(table) − f)")};
  s.timeName = "µs per table (median)";
  s.settingName = "entries";
  s.timeScale = 1000;
  s.code = {"effects/fog"};
  for (const Series& x : allSeries()) {
    if (groupOf(x.name) != x.name) continue;
    const std::string what = x.name.find("sunset") != std::string::npos ? "a height-fog table: " + x.name
                             : x.fog.type == fg::FogType::kHeight      ? "a height-fog table (" + x.name + ")"
                                                                       : "a fog table (" + x.name + ")";
    s.asks.push_back({x.name, what, {{"fog", {{"fogType", fg::toString(x.fog.type)}}}}});
  }
  s.measure = measure;
  s.conclude = conclude;
  return s;
}

}  // namespace report
