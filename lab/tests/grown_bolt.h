// What every bolt a bench law grows must be, and the layout the tests grow them in
// (tests/half_field_test.cpp, exposure_law_test.cpp).
#pragma once

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include <effects/lightning.h>

#include "layouts.h"

namespace bench::shape {

namespace lt = effects::lightning;

// The shape bench's open layout at eta 2.
inline lt::Params openLayout(int s) {
  lt::Params p = layout("open", s);
  p.eta = 2;
  return p;
}

// A bolt grown by a bench law in layout p is a tree of 8-neighbour steps from the start to the
// target, each cell once, the same for a seed and not for another.
inline void expectGrowsATree(lt::Params p, const std::function<lt::Bolt(const lt::Params&)>& grow) {
  p.seed = 7;
  const lt::Bolt a = grow(p), b = grow(p);
  const lt::Cell t = p.targets.at(0);
  ASSERT_GT(a.nodes.size(), size_t(std::max(std::abs(t.x - p.start.x), std::abs(t.y - p.start.y))));  // a path
  EXPECT_TRUE(a.nodes.front().cell == p.start);
  EXPECT_TRUE(a.nodes.back().cell == p.targets[0]);
  std::set<std::tuple<int, int>> seen;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const lt::Node& n = a.nodes[i];
    EXPECT_TRUE(seen.insert({n.cell.x, n.cell.y}).second) << "cell " << n.cell.x << "," << n.cell.y << " twice";
    if (i == 0) continue;
    ASSERT_GE(n.parent, 0);
    ASSERT_LT(size_t(n.parent), i);
    const lt::Cell q = a.nodes[size_t(n.parent)].cell;
    EXPECT_LE(std::max(std::abs(q.x - n.cell.x), std::abs(q.y - n.cell.y)), 1);
  }
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) EXPECT_TRUE(a.nodes[i].cell == b.nodes[i].cell);
  p.seed = 8;
  const lt::Bolt c = grow(p);
  bool differs = c.nodes.size() != a.nodes.size();
  for (size_t i = 0; !differs && i < a.nodes.size(); ++i) differs = !(a.nodes[i].cell == c.nodes[i].cell);
  EXPECT_TRUE(differs);
}

}  // namespace bench::shape
