// A Fenwick (binary indexed) tree over non-negative weights: replace one weight, and find the
// index at a cumulative weight, in O(log n). The fast method samples its candidates with it,
// so a step costs O(log n) however many candidates the bolt has gathered. Replacing weights
// by subtraction lets the sums drift by rounding: callers rebuild it now and then.
#pragma once

#include <cstddef>
#include <vector>

namespace effects::lightning::detail {

class WeightTree {
 public:
  // O(n): the tree over `weights` (its size is fixed until the next rebuild).
  template <class Weight>
  void rebuild(size_t n, Weight&& weight) {
    w_.resize(n);
    tree_.assign(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i) tree_[i + 1] = w_[i] = weight(i);
    for (size_t i = 1; i <= n; ++i)
      if (size_t j = i + (i & (~i + 1)); j <= n) tree_[j] += tree_[i];
  }
  size_t size() const { return w_.size(); }
  void set(size_t i, double weight) {
    const double delta = weight - w_[i];
    w_[i] = weight;
    for (size_t k = i + 1; k < tree_.size(); k += k & (~k + 1)) tree_[k] += delta;
  }
  double total() const {
    double s = 0;
    for (size_t k = w_.size(); k > 0; k -= k & (~k + 1)) s += tree_[k];
    return s;
  }
  // The smallest i whose cumulative weight w_0 + ... + w_i exceeds u; size() when none does.
  size_t find(double u) const {
    size_t pos = 0, step = 1;
    while (step * 2 <= w_.size()) step *= 2;
    for (; step > 0; step /= 2)
      if (pos + step <= w_.size() && tree_[pos + step] <= u) {
        pos += step;
        u -= tree_[pos];
      }
    return pos;
  }

 private:
  std::vector<double> tree_;  // 1-based partial sums
  std::vector<double> w_;     // the weights as the tree holds them
};

}  // namespace effects::lightning::detail
