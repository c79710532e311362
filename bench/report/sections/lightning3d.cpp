// Lightning on 3-D grids (26-neighbourhood, 32³; 16³ in the quick run): the same two measures
// as the 2-D section.
#include "lightning_common.h"
#include "sections.h"

namespace report {

Section lightning3dSection() {
  Section s;
  s.id = "lightning3d";
  s.effect = "lightning";
  s.title = "Lightning in 3-D: the candidate distribution and the fractal dimension against DBM";
  s.reference =
      "TV: the 3-D DBM distribution from a converged solve (7-point Laplacian, MGPCG, relative residual 1e-10) on "
      "the same bolt state, every step; ΔD: the mean box-counting dimension D_ref of 3-D DBM (the default solver) at "
      "the same size and seeds";
  s.metrics = {tvMetric(), fdMetric()};
  s.timeName = "ms per bolt (median)";
  s.settingName = "setting";
  s.noteName = "D ± sd, TV ± sd";
  s.code = {"effects/lightning"};
  s.asks = {{"32³, 26-nbhd", "a bolt in 32³ to a point", gridRequest(32, 26, true)}};
  s.measure = [](Run& run) { lightningRows(run, run.quick ? 16 : 32, 26, true); };
  s.conclude = [](const Section&, const Run& run) { return lightningConclusion(run); };
  return s;
}

}  // namespace report
