// The glow of a bolt through fog (its atmospheric point spread function): each fast kernel
// against the series (the share of light it misplaces within 90 degrees), per medium; and the
// series itself against the photon simulation, the independent check.
#include <effects/glow.h>

#include "sections.h"

namespace report {

namespace {

namespace gw = effects::glow;

volatile double sink = 0;

struct Case {
  double t, q;
};

std::vector<Case> cases(bool quick) {
  return quick ? std::vector<Case>{{2, 0.9}} : std::vector<Case>{{1.2, 0.9}, {2, 0.9}, {4, 0.9}, {2, 0.5}, {8, 0.99}};
}

std::string groupOf(const Case& c) {
  char group[64];
  std::snprintf(group, sizeof group, "T %g, q %g", c.t, c.q);
  return group;
}

void measure(Run& run) {
  for (const Case& c : cases(run.quick)) {
    const gw::Medium m{c.t, c.q};
    const std::string group = groupOf(c);
    for (gw::Method method : {gw::Method::kGaussian, gw::Method::kGaussians2, gw::Method::kGaussians3, gw::Method::kTable}) {
      for (int samples : method == gw::Method::kTable ? std::vector<int>{8, 32, 128} : std::vector<int>{64}) {
        gw::KernelOptions o;
        o.method = method;
        o.samples = samples;
        o.measureError = false;
        Row r;
        r.series = gw::toString(method);
        r.setting = group + ": " + (method == gw::Method::kTable ? "table of " + std::to_string(samples) : "fitted");
        r.group = group;
        r.request = {{"glow", {{"kernel", gw::toString(method)}}}};
        if (method == gw::Method::kTable) r.request["glow"]["samples"] = samples;
        r.ticket = run.repeat("glow " + group + " " + gw::toString(method) + std::to_string(samples), run.quick ? 3 : 5,
                              [m, o] { sink = sink + gw::kernel(m, o).value().haloRadius; });
        o.measureError = true;
        const gw::Kernel k = gw::kernel(m, o).value();
        r.errors["misplaced"] = *k.misplaced;
        r.note = fmt(k.haloRadius * 180 / kPi, 3);
        run.rows.push_back(r);
      }
    }
    // The series against the photons: the share of light the series puts elsewhere than they do.
    gw::MonteCarloOptions mo;
    mo.photons = run.quick ? 4000 : 40000;
    const gw::MonteCarlo mc = gw::monteCarlo(m, mo);
    const std::vector<double> series = gw::apsfBinned(m, mc.edges);
    double misplaced = 0, noise = 0;
    for (size_t b = 0; b < series.size(); ++b) {
      const double omega = 2 * kPi * (std::cos(mc.edges[b]) - std::cos(mc.edges[b + 1]));
      misplaced += omega * std::abs(series[b] - mc.values[b]);
      noise += omega * mc.errors[b];
    }
    Row r;
    r.series = "series vs photons";
    r.setting = group + ": series (" + std::to_string(mo.photons) + " photons; their noise " + fmt(noise, 2) + ")";
    r.group = group;
    r.errors["misplaced"] = misplaced;
    r.note = "—";
    r.ticket = run.repeat("glow series " + group, run.quick ? 3 : 5, [m, mc] { sink = sink + gw::apsfBinned(m, mc.edges).front(); });
    run.rows.push_back(r);
  }
}

std::string conclude(const Section&, const Run& run) {
  double worstSeries = 0, worstFit = 0;
  for (const Row& r : run.rows) {
    if (r.series == "series vs photons") worstSeries = std::max(worstSeries, errorOf(r, "misplaced"));
    if (r.series == "gaussians-3") worstFit = std::max(worstFit, errorOf(r, "misplaced"));
  }
  return "Three fitted Gaussians misplace at most " + fmt(worstFit, 2) +
         " of the light against the series (the renderer's default), a 32-entry table less and in a hundredth of the "
         "time (the fit is the cost). The series itself is not the physics: against photons through the same medium "
         "it misplaces up to " + fmt(worstSeries, 2) +
         " of the light, of at most 2 (its halo is too wide: at large T it tends to (1 + mu), where diffusion gives "
         "T(1 - q) + mu; docs/effects.md §5).";
}

}  // namespace

Section glowSection() {
  Section s;
  s.id = "glow-apsf";
  s.effect = "glow";
  s.title = "Lightning glow through fog: APSF kernels against the series (Narasimhan & Nayar 2003), and the series against photons";
  s.reference =
      "the APSF series summed to 1e-12 (glow::apsf) on a grid 4x the kernel's, over [0, 90 deg]; for the series row, "
      "glow::monteCarlo's photons in 30 bins over [0, 180 deg] (the whole sphere)";
  s.metrics = {{"misplaced", "misplaced", "light misplaced (integral of |K - K_ref| dOmega)", 0.05,
                "5 % of the halo's light elsewhere: a visibly different halo"}};
  s.timeName = "ms per kernel (median)";
  s.settingName = "kernel";
  s.noteName = "halo radius (deg)";
  s.code = {"effects/glow"};
  for (const Case& c : cases(false)) {
    char what[96];
    std::snprintf(what, sizeof what, "a glow kernel through fog of optical thickness %g, q %g", c.t, c.q);
    s.asks.push_back({groupOf(c), what, {{"glow", {{"opticalThickness", c.t}, {"forwardScattering", c.q}}}}});
  }
  s.measure = measure;
  s.conclude = conclude;
  return s;
}

}  // namespace report
