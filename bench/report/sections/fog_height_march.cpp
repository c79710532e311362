// Height fog's closed-form optical depth against ray marching, the usual engine method.
#include "fog_common.h"
#include "sections.h"

namespace report {

namespace {

volatile double sink = 0;

constexpr double kA = 0.05, kB = 0.3, kH = 0, kOy = 2, kDistance = 150;

std::vector<double> directions() {
  std::vector<double> dirs;
  for (int i = 0; i < 64; ++i) dirs.push_back(-0.3 + 0.6 * i / 63.0);
  return dirs;
}

double exact(double dy) { return std::exp(-fg::heightOpticalDepth(kA, kB, kH, kOy, dy, kDistance)); }
double marched(double dy, int steps) { return std::exp(-fg::heightOpticalDepthMarched(kA, kB, kH, kOy, dy, kDistance, steps)); }

void measure(Run& run) {
  const std::vector<double> dirs = directions();
  Row closed;
  closed.series = "closed form";
  closed.setting = "exact";
  closed.request = {{"fog", {{"fogType", "HEIGHT"}}}};
  closed.errors["maxError"] = 0;
  closed.ticket = run.repeat("height closed form", run.quick ? 5 : 51, [dirs] {
    for (double dy : dirs) sink = sink + exact(dy);
  });
  run.rows.push_back(closed);
  for (int steps : run.quick ? std::vector<int>{4, 16, 64} : std::vector<int>{4, 8, 16, 32, 64, 128, 256, 512, 1024}) {
    double worst = 0;
    for (double dy : dirs) worst = std::max(worst, std::abs(marched(dy, steps) - exact(dy)));
    Row r;
    r.series = "ray marching";
    r.setting = std::to_string(steps) + " steps";
    r.errors["maxError"] = worst;
    r.ticket = run.repeat("height march " + std::to_string(steps), run.quick ? 5 : 21, [dirs, steps] {
      for (double dy : dirs) sink = sink + marched(dy, steps);
    });
    run.rows.push_back(r);
  }
}

std::string conclude(const Section&, const Run& run) {
  const Row& exactRow = run.rows.front();
  const Row* enough = fastestWithin(run, "maxError", 1.0 / 255, "ray marching");
  std::string c = "The closed form is exact and costs " + fmt(exactRow.ms * 1000) + " µs for 64 rays";
  if (enough) c += "; ray marching needs " + enough->setting + " for 8-bit precision at " + fmt(enough->ms * 1000) + " µs";
  return c + ": the closed form wins on both axes.";
}

}  // namespace

Section fogHeightMarchSection() {
  Section s;
  s.id = "fog-height-march";
  s.effect = "fog";
  s.title = "Height fog: closed-form optical depth against ray marching";
  s.reference =
      "the closed form tau = a e^(-b(o_y-h)) t (1-e^(-x))/x (exact; checked against 200 000-step marching in the tests)";
  s.metrics = {fogMetric("maxError", "max abs(f_marched − f_exact), 64 rays")};
  s.timeName = "µs for 64 rays (median)";
  s.settingName = "steps";
  s.timeScale = 1000;
  s.code = {"effects/fog"};
  s.measure = measure;
  s.conclude = conclude;
  return s;
}

}  // namespace report
