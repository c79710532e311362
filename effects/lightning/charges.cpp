// Kim, Sewall, Sud & Lin 2007: the potential of point charges, updated incrementally (one new
// term per candidate per step), with no linear solve: phi_i = sum_j (1 - R1/r_ij), R1 = h/2,
// the target the positive charge paired with every bolt charge, normalised to [0, 1] over the
// candidates and raised to their dimension parameter (calibratedChargesEta() by default).
#include <algorithm>
#include <cmath>

#include "growth.h"

namespace effects::lightning::detail {

namespace {

class Charges final : public PhiMethod {
 public:
  explicit Charges(Growth& growth) : s_(growth) {}

  double exponent() const override { return exponent_; }
  void cellAdded(Cell c) override {
    for (auto& cand : s_.cands) cand.charge += 1.0 / std::hypot(double(cand.cell.x - c.x), double(cand.cell.y - c.y));
  }
  void candidateAdded(Candidate& cand) override {
    for (const Node& n : s_.bolt.nodes)
      cand.charge += 1.0 / std::hypot(double(cand.cell.x - n.cell.x), double(cand.cell.y - n.cell.y));
  }
  // phi_i = R1 * sum_j (1/r_it - 1/r_ij), then normalised over the candidates.
  void logPhi(std::vector<double>& out) override {
    const std::vector<Candidate>& cands = s_.cands;
    out.resize(cands.size());
    const double R1 = 0.5, n = double(s_.bolt.nodes.size());
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < cands.size(); ++i) {
      const Candidate& c = cands[i];
      double rt = std::max(0.5, std::hypot(double(c.cell.x - s_.attractor.x), double(c.cell.y - s_.attractor.y)));
      out[i] = R1 * (n / rt - c.charge);
      lo = std::min(lo, out[i]);
      hi = std::max(hi, out[i]);
    }
    for (double& v : out) v = hi > lo ? std::log((v - lo) / (hi - lo)) : 0.0;
  }
  void report(Stats& s) const override { s.counters["chargesEta"] = exponent_; }

 private:
  Growth& s_;
  const double exponent_ = s_.p.chargesEta > 0 ? s_.p.chargesEta : calibratedChargesEta(s_.p);
};

}  // namespace

std::unique_ptr<PhiMethod> chargesMethod(Growth& growth) { return std::make_unique<Charges>(growth); }

}  // namespace effects::lightning::detail
