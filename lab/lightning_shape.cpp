// The fast method's (or the charges method's) bolts against DBM's by shape, over seeds: the
// box-count curve N(s) at every scale, the mass-radius curve, branch segment lengths, branching
// angles and tips counted two ways (lab/bolt_shape.h). Each comparison's noise level comes
// from DBM against DBM: random half-splits of the DBM seeds, the 95th percentile of the same
// statistic, scaled to the sample sizes compared. "meets" = the method's distance from DBM is
// within that noise: indistinguishable at these seeds.
//
//   lightning_shape [--size 128] [--fast-seeds 40] [--dbm-seeds 30] [--eta 1,2,3]
//                   [--method fast|charges|half-field|exposure] [--law ...] [--splits 40]
//                   [--geometry open]
//
// half-field and exposure: the candidate laws of lab/half_field.h and lab/exposure_law.h
// (2-D layouts with one point target), with their constants or, after --method, --law's:
// half-field phi,n1,n4,n3[,coarse factor[,free,reach]]; exposure g,p,n1,n4,n3,e[,reach].
//
// Geometries (--size s): lab/layouts.h.
// Where the strike ends on a region, the struck cell's distance from below the start is
// compared too (KS). Times are per bolt, growing only (not calibrate(), not the measures).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <effects/lightning.h>

#include "bolt_shape.h"
#include "exposure_law.h"
#include "half_field.h"
#include "layouts.h"

namespace lt = effects::lightning;
namespace sh = bench::shape;

namespace {

struct Sample {
  std::vector<sh::Measures> bolts;
  double msPerBolt = 0;
};

// A law of the bench instead of the method (2-D, one point target).
enum class Law { kNone, kHalfField, kExposure };
struct Laws {
  Law which = Law::kNone;
  sh::HalfFieldLaw halfField;
  sh::ExposureLaw exposure;
};

Sample grow(const lt::Params& base, lt::Method method, double eta, int seeds, uint64_t firstSeed,
            const Laws& law = {}) {
  Sample s;
  double ms = 0;  // growing only: not calibrate(), not the shape measures
  for (int k = 0; k < seeds; ++k) {
    lt::Params p = base;
    p.method = method;
    p.eta = eta;
    p.seed = firstSeed + uint64_t(k);
    lt::calibrate(p);  // what the server does for every request
    const auto t0 = std::chrono::steady_clock::now();
    lt::Bolt bolt;
    if (law.which != Law::kNone) {
      bolt = law.which == Law::kHalfField ? sh::growHalfField(p, law.halfField) : sh::growExposureLaw(p, law.exposure);
    } else {
      auto grown = lt::grow(p);
      if (!grown.ok()) {
        std::fprintf(stderr, "grow failed: %s\n", grown.error().message.c_str());
        std::exit(1);
      }
      bolt = std::move(grown.value());
    }
    ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    s.bolts.push_back(sh::measure(bolt, p.width, p.height, p.depth));
  }
  s.msPerBolt = ms / seeds;
  return s;
}

// One statistic between two sets of bolts.
using Statistic = std::function<double(const std::vector<sh::Measures>&, const std::vector<sh::Measures>&)>;

std::vector<std::vector<double>> curves(const std::vector<sh::Measures>& b, std::vector<double> sh::Measures::*field) {
  std::vector<std::vector<double>> out;
  for (const auto& m : b) out.push_back(m.*field);
  return out;
}
std::vector<std::vector<double>> scalars(const std::vector<sh::Measures>& b, double sh::Measures::*field) {
  std::vector<std::vector<double>> out;
  for (const auto& m : b) out.push_back({m.*field});
  return out;
}
std::vector<double> pooled(const std::vector<sh::Measures>& b, std::vector<double> sh::Measures::*field) {
  std::vector<double> out;
  for (const auto& m : b) out.insert(out.end(), (m.*field).begin(), (m.*field).end());
  return out;
}

struct Row {
  std::string name;
  Statistic stat;
  bool ks;  // a KS distance (scaled by sample size for the noise), else a Welch z
};

}  // namespace

int main(int argc, char** argv) {
  int size = 128, fastSeeds = 40, dbmSeeds = 30, splits = 40;
  std::string geometry = "open";
  std::vector<double> etas = {1, 2, 3};
  lt::Method method = lt::Method::kFast;
  Laws law;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--size") size = std::atoi(v.c_str());
    else if (a == "--fast-seeds") fastSeeds = std::atoi(v.c_str());
    else if (a == "--dbm-seeds") dbmSeeds = std::atoi(v.c_str());
    else if (a == "--splits") splits = std::atoi(v.c_str());
    else if (a == "--geometry") geometry = v;
    else if (a == "--method") {
      method = v == "charges" ? lt::Method::kCharges : lt::Method::kFast;
      law.which = v == "half-field" ? Law::kHalfField : v == "exposure" ? Law::kExposure : Law::kNone;
    } else if (a == "--law") {
      sh::HalfFieldLaw& f = law.halfField;
      sh::ExposureLaw& e = law.exposure;
      if (law.which == Law::kHalfField)
        std::sscanf(v.c_str(), "%lf,%lf,%lf,%lf,%d,%lf,%d", &f.phi, &f.n1, &f.n4, &f.n3, &f.coarse, &f.free, &f.reach);
      else if (law.which == Law::kExposure)
        std::sscanf(v.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%d", &e.g, &e.p, &e.n1, &e.n4, &e.n3, &e.e, &e.reach);
      else {
        std::fprintf(stderr, "--law after --method half-field or exposure\n");
        return 2;
      }
    } else if (a == "--eta") {
      etas.clear();
      std::stringstream ss(v);
      for (std::string e; std::getline(ss, e, ',');) etas.push_back(std::atof(e.c_str()));
    } else {
      std::fprintf(stderr, "unknown flag %s\n", a.c_str());
      return 2;
    }
  }
  std::vector<Row> rows = {
      {"box counts N(s), every scale", [](auto& a, auto& b) { return sh::curveZ(curves(a, &sh::Measures::boxCounts), curves(b, &sh::Measures::boxCounts)); }, false},
      {"mass-radius M(r)", [](auto& a, auto& b) { return sh::curveZ(curves(a, &sh::Measures::massRadius), curves(b, &sh::Measures::massRadius)); }, false},
      {"tips: tree leaves", [](auto& a, auto& b) { return sh::curveZ(scalars(a, &sh::Measures::leafTips), scalars(b, &sh::Measures::leafTips)); }, false},
      {"tips: one 8-neighbour", [](auto& a, auto& b) { return sh::curveZ(scalars(a, &sh::Measures::neighbourTips), scalars(b, &sh::Measures::neighbourTips)); }, false},
      {"cells", [](auto& a, auto& b) { return sh::curveZ(scalars(a, &sh::Measures::cells), scalars(b, &sh::Measures::cells)); }, false},
      {"segment lengths (KS)", [](auto& a, auto& b) { return sh::ks(pooled(a, &sh::Measures::segments), pooled(b, &sh::Measures::segments)); }, true},
      {"branching angles (KS)", [](auto& a, auto& b) { return sh::ks(pooled(a, &sh::Measures::angles), pooled(b, &sh::Measures::angles)); }, true},
  };
  const lt::Params base = sh::layout(geometry, size);
  if (!base.targetRegion.empty())  // where on the ground the strike lands
    rows.push_back({"struck cell's offset (KS)", [](auto& a, auto& b) {
                      std::vector<double> x, y;
                      for (const auto& m : a) x.push_back(m.struckOffset);
                      for (const auto& m : b) y.push_back(m.struckOffset);
                      return sh::ks(x, y);
                    }, true});
  if (law.which != Law::kNone && (base.depth || base.targets.size() != 1 || !base.targetRegion.empty())) {
    std::fprintf(stderr, "--method half-field or exposure: 2-D layouts with one point target (open, off-axis, wall)\n");
    return 2;
  }
  const char* name = law.which == Law::kHalfField  ? "half-field"
                     : law.which == Law::kExposure ? "exposure"
                                                   : lt::toString(method);
  std::printf("# %s against dbm by shape: %s, %d x %d%s\n\n", name, geometry.c_str(), base.width, base.height,
              base.depth ? (" x " + std::to_string(base.depth)).c_str() : "");
  std::printf("%d %s and %d dbm bolts per eta; noise: 95th percentile over %d random half-splits of the dbm "
              "bolts (KS distances scaled to the sizes compared); meets = within the noise.\n\n",
              fastSeeds, name, dbmSeeds, splits);
  std::printf("| eta | measure | %s vs dbm | noise (dbm vs dbm) | |\n|---|---|---|---|---|\n", name);
  std::mt19937 rng(49);
  for (double eta : etas) {
    const Sample fast = grow(base, method, eta, fastSeeds, 1000, law);
    const Sample dbm = grow(base, lt::Method::kDbm, eta, dbmSeeds, 5000);
    for (const Row& row : rows) {
      const double d = row.stat(fast.bolts, dbm.bolts);
      std::vector<double> noise;
      std::vector<sh::Measures> shuffled = dbm.bolts;
      for (int k = 0; k < splits; ++k) {
        std::shuffle(shuffled.begin(), shuffled.end(), rng);
        const size_t half = shuffled.size() / 2;
        std::vector<sh::Measures> a(shuffled.begin(), shuffled.begin() + long(half)), b(shuffled.begin() + long(half), shuffled.end());
        noise.push_back(row.stat(a, b));
      }
      std::sort(noise.begin(), noise.end());
      double level = noise[std::min(noise.size() - 1, size_t(0.95 * double(noise.size())))];
      if (row.ks)  // KS grows like sqrt(1/n1 + 1/n2): from the halves' sizes to the ones compared
        level *= std::sqrt(1.0 / fastSeeds + 1.0 / dbmSeeds) / std::sqrt(4.0 / dbmSeeds);
      std::printf("| %g | %s | %.3g | %.3g | %s |\n", eta, row.name.c_str(), d, level, d <= level ? "meets" : "**differs**");
    }
    double dFast = 0, dDbm = 0;
    for (const auto& m : fast.bolts) dFast += sh::slope(m.boxCounts) / double(fast.bolts.size());
    for (const auto& m : dbm.bolts) dDbm += sh::slope(m.boxCounts) / double(dbm.bolts.size());
    std::printf("| %g | box-count slope (mean) | %.3f vs %.3f | | %.3g / %.3g ms per bolt |\n", eta, dFast, dDbm,
                fast.msPerBolt, dbm.msPerBolt);
    if (law.which != Law::kNone)  // what the law would replace, timed in the same run
      std::printf("| %g | fast calibrated, same seeds | | | %.3g ms per bolt |\n", eta,
                  grow(base, lt::Method::kFast, eta, fastSeeds, 1000).msPerBolt);
  }
  return 0;
}
