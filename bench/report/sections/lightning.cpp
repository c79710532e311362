// Lightning on 2-D grids: every setting a client can send, against exact DBM, by two measures:
// the per-step candidate distribution (TV, against a converged solve on the same bolt state)
// and the fractal dimension over seeds (|D − D_ref|).
#include "lightning_common.h"
#include "sections.h"

namespace report {

Section lightningSection() {
  Section s;
  s.id = "lightning";
  s.effect = "lightning";
  s.title = "Lightning: the candidate distribution and the fractal dimension against DBM";
  s.reference =
      "TV: the DBM distribution from a converged solve (MGPCG, relative residual 1e-10) on the same bolt state, every "
      "step (up to 128²); ΔD: the mean box-counting dimension D_ref of exact DBM (the default solver: the capacitance "
      "method while its limit allows, then MGPCG at tolerance 1e-8) at the same size and seeds";
  s.metrics = {tvMetric(), fdMetric()};
  s.timeName = "ms per bolt (median)";
  s.settingName = "setting";
  s.noteName = "D ± sd, TV ± sd";
  s.code = {"effects/lightning"};
  for (int n : {64, 128, 256})
    for (int hood : {8, 4})
      s.asks.push_back({std::to_string(n) + "², " + std::to_string(hood) + "-nbhd",
                        "a bolt on " + std::to_string(n) + "² to a point" + (hood == 4 ? ", 4-neighbourhood" : ""),
                        gridRequest(n, hood, false)});
  s.measure = [](Run& run) {
    for (int n : run.quick ? std::vector<int>{32} : std::vector<int>{64, 128, 256})
      for (int hood : {8, 4}) lightningRows(run, n, hood, false);
  };
  s.conclude = [](const Section&, const Run& run) { return lightningConclusion(run); };
  return s;
}

}  // namespace report
