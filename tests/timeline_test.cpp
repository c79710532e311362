// effects/lightning timeline: the strike's leader, strokes and fade, as a client plays them.
#include <cmath>

#include <gtest/gtest.h>

#include <effects/lightning.h>

#include "fixtures.h"

namespace effects::lightning {
namespace {

struct Strike {
  Bolt bolt;
  std::vector<Polyline> lines;
  Timeline tl;
};

Strike strike(uint64_t seed, const TimelineParams& t = {}, int n = 96) {
  auto r = grow(fixtures::lightningLayout(n, Method::kFast, seed));
  EXPECT_TRUE(r.ok());
  Strike s{std::move(r.value()), {}, {}};
  s.lines = polylines(s.bolt, ShapeParams{});
  auto tl = timeline(s.bolt, s.lines, t);
  EXPECT_TRUE(tl.ok()) << (tl.ok() ? "" : tl.error().field + ": " + tl.error().message);
  if (tl.ok()) s.tl = std::move(tl.value());
  return s;
}

// The contract: bad input comes back as an Error naming it, never a crash or a wrong answer.
TEST(Timeline, BadInputIsAnErrorNamingIt) {
  const Strike s = strike(1);
  const auto field = [](const Result<Timeline>& r) { return r.ok() ? std::string("(ok)") : r.error().field; };
  EXPECT_EQ(field(timeline(Bolt{}, {}, TimelineParams{})), "/bolt");  // a default Bolt: no nodes
  TimelineParams negative;
  negative.timeScale = -1;
  EXPECT_EQ(field(timeline(s.bolt, s.lines, negative)), "/timeScale");
  TimelineParams nan;
  nan.cellSize = std::nan("");
  EXPECT_EQ(field(timeline(s.bolt, s.lines, nan)), "/timeline/cellSize");
  Bolt cyclic = s.bolt;  // a node whose parent comes after it
  cyclic.nodes[1].parent = int(cyclic.nodes.size()) - 1;
  EXPECT_EQ(field(timeline(cyclic, s.lines, TimelineParams{})), "/bolt");
  Bolt shortMain = s.bolt;
  shortMain.mainChannel.push_back(int(s.bolt.nodes.size()) + 5);
  EXPECT_EQ(field(timeline(shortMain, s.lines, TimelineParams{})), "/bolt");
  std::vector<Polyline> foreign = s.lines;  // a vertex naming a node past this bolt's
  foreign[0].vertices.back().node = int(s.bolt.nodes.size()) + 3;
  EXPECT_EQ(field(timeline(s.bolt, foreign, TimelineParams{})), "/lines");
}

TEST(Timeline, MonotoneFiniteAndWithinTheStrike) {
  for (uint64_t seed : {1, 2, 3}) {
    const Strike s = strike(seed);
    const Timeline& tl = s.tl;
    ASSERT_EQ(tl.leader.size(), s.lines.size());
    EXPECT_GT(tl.connect, 0);
    EXPECT_GT(tl.duration, tl.strokes.back().t);
    for (size_t i = 0; i < s.lines.size(); ++i) {
      ASSERT_EQ(tl.leader[i].size(), s.lines[i].vertices.size());
      for (size_t j = 0; j < tl.leader[i].size(); ++j) {
        EXPECT_TRUE(std::isfinite(tl.leader[i][j]) && tl.leader[i][j] >= 0 && tl.leader[i][j] <= tl.duration);
        EXPECT_TRUE(std::isfinite(tl.strokeDelay[i][j]) && tl.strokeDelay[i][j] >= 0);
        if (j) {
          EXPECT_GE(tl.leader[i][j], tl.leader[i][j - 1]) << "line " << i << " vertex " << j;
        }
      }
    }
    // The main channel: the leader arrives at its end at connect; the stroke runs back up it.
    const auto& mainLeader = tl.leader[0];
    EXPECT_DOUBLE_EQ(mainLeader.back(), tl.connect);
    EXPECT_DOUBLE_EQ(tl.strokeDelay[0].back(), 0);
    for (size_t j = 1; j < mainLeader.size(); ++j) EXPECT_LE(tl.strokeDelay[0][j], tl.strokeDelay[0][j - 1]);
    for (size_t k = 1; k < tl.keyframes.size(); ++k) EXPECT_GT(tl.keyframes[k].t, tl.keyframes[k - 1].t);
    for (const Keyframe& k : tl.keyframes)
      for (float v : {k.leader, k.main, k.branches}) EXPECT_TRUE(v >= 0 && v <= 1) << k.t;
    EXPECT_EQ(tl.keyframes.back().main, 0);
  }
}

TEST(Timeline, PhysicalDefaultsAndTimeScale) {
  const Strike s = strike(5);
  const Timeline& tl = s.tl;
  ASSERT_GE(tl.strokes.size(), 3u);
  ASSERT_LE(tl.strokes.size(), 4u);
  EXPECT_DOUBLE_EQ(tl.strokes[0].t, tl.connect);
  EXPECT_EQ(tl.strokes[0].peak, 1.0f);
  for (size_t k = 1; k < tl.strokes.size(); ++k) {
    const double gap = tl.strokes[k].t - tl.strokes[k - 1].t;
    EXPECT_TRUE(gap >= 0.040 && gap <= 0.060) << gap;
    EXPECT_LT(tl.strokes[k].peak, 1.0f);
  }
  // 96 cells of 25 m, 50 m steps of 20-50 us plus a detour: milliseconds, not seconds.
  EXPECT_GT(tl.connect, 1200.0 / 50 * 20e-6);
  EXPECT_LT(tl.connect, 0.02);
  // The return stroke climbs the main channel at ~c/3: microseconds.
  EXPECT_LT(tl.strokeDelay[0].front(), 1e-4);
  // The glow is gone ~100-250 ms after the last stroke.
  EXPECT_GT(tl.duration - tl.strokes.back().t, 0.1);
  EXPECT_LT(tl.duration - tl.strokes.back().t, 0.25);
  // Every stroke re-lights the main channel; only the first lights the branches.
  for (const Stroke& st : tl.strokes) {
    EXPECT_GT(channelsAt(tl, st.t + 1e-3).main, 0.4f * st.peak);
    if (&st != &tl.strokes[0]) {
      EXPECT_LT(channelsAt(tl, st.t + 1e-3).branches, 0.01f);
    }
  }

  TimelineParams slow;
  slow.timeScale = 10;
  const Strike t = strike(5, slow);
  EXPECT_NEAR(t.tl.connect, 10 * tl.connect, 1e-12);
  EXPECT_NEAR(t.tl.duration, 10 * tl.duration, 1e-9);
  ASSERT_EQ(t.tl.keyframes.size(), tl.keyframes.size());
  EXPECT_EQ(t.tl.keyframes[5].main, tl.keyframes[5].main);
}

TEST(Timeline, ShapeAndAnimationSeedsAreIndependent) {
  TimelineParams a, b;
  a.seed = 1, b.seed = 2;
  const Strike x = strike(7, a), y = strike(7, b), z = strike(7, a);
  EXPECT_EQ(x.bolt.nodes.size(), y.bolt.nodes.size());  // the same bolt
  EXPECT_NE(x.tl.connect, y.tl.connect);                // animated otherwise
  EXPECT_EQ(x.tl.connect, z.tl.connect);                // deterministic
  EXPECT_EQ(x.tl.leader, z.tl.leader);
  const Strike w = strike(8, a);  // another bolt, the same animation seed
  EXPECT_NE(w.bolt.nodes.size() == x.bolt.nodes.size() && w.tl.leader == x.tl.leader, true);
}

TEST(Timeline, ExposureShowsTheLeaderThenTheStrokeThenNothing) {
  const Strike s = strike(3);
  const Timeline& tl = s.tl;
  EXPECT_TRUE(exposure(tl, s.lines, -1, -0.5).empty());
  // Halfway through the leader: part of the main channel, dim.
  const auto half = exposure(tl, s.lines, 0.5 * tl.connect, 0.5 * tl.connect);
  ASSERT_FALSE(half.empty());
  EXPECT_LT(half[0].vertices.size(), s.lines[0].vertices.size());
  for (const auto& v : half[0].vertices) EXPECT_LE(v.intensity, 0.31f);
  // A frame holding the first stroke: the whole main channel at full brightness, branches lit.
  const auto flash = exposure(tl, s.lines, tl.connect, tl.connect + 1.0 / 30);
  ASSERT_FALSE(flash.empty());
  EXPECT_EQ(flash[0].vertices.size(), s.lines[0].vertices.size());
  for (const auto& v : flash[0].vertices) EXPECT_GT(v.intensity, 0.9f);
  EXPECT_GT(flash.size(), 1u);
  // A frame between strokes: the main channel glows dimly, branches are dark.
  const double between = 0.5 * (tl.strokes[0].t + tl.strokes[1].t);
  const auto glow = exposure(tl, s.lines, between, between);
  ASSERT_FALSE(glow.empty());
  EXPECT_TRUE(glow[0].main);
  EXPECT_LT(glow[0].vertices[0].intensity, 0.5f);
  for (size_t i = 1; i < glow.size(); ++i)
    for (const auto& v : glow[i].vertices) EXPECT_LT(v.intensity, 0.1f);
  // A frame's peak is what a client's per-vertex formula gives at the brightest instant.
  EXPECT_NEAR(glow[0].vertices[3].intensity, vertexBrightness(tl, s.lines, 0, 3, between), 1e-6);
  EXPECT_TRUE(exposure(tl, s.lines, tl.duration + 0.01, tl.duration + 0.02).empty());
}

// A slow return stroke on a long channel: the strike lasts until its farthest vertex is dark.
TEST(Timeline, DurationCoversTheSlowestStroke) {
  TimelineParams p;
  p.returnStrokeSpeed = 1e5;
  p.cellSize = 1e4;
  const Strike s = strike(4, p, 48);
  double latest = 0;
  for (const auto& line : s.tl.strokeDelay)
    for (double d : line) latest = std::max(latest, d);
  EXPECT_GT(latest, 1.0);  // seconds of travel along the channel
  EXPECT_GE(s.tl.duration, s.tl.strokes.back().t + latest);
  for (size_t i = 0; i < s.lines.size(); ++i)
    for (size_t j = 0; j < s.lines[i].vertices.size(); ++j)
      EXPECT_LT(vertexBrightness(s.tl, s.lines, i, j, s.tl.duration), 0.01) << i << " " << j;
}

TEST(Timeline, ExtremeParametersStayFinite) {
  TimelineParams p;
  p.timeScale = 1e6;
  p.cellSize = 1e4;
  p.leaderStep = 1;  // a step per metre: capped work per vertex, long leaders
  p.strokes = 64;
  p.pauseMinUs = p.pauseMaxUs = 1e6;
  const Strike s = strike(2, p, 48);
  EXPECT_TRUE(std::isfinite(s.tl.duration));
  EXPECT_EQ(s.tl.strokes.size(), 64u);
  for (const auto& line : s.tl.leader)
    for (double t : line) EXPECT_TRUE(std::isfinite(t));
  EXPECT_FALSE(validate(p).has_value());
  p.timeScale = 0;
  EXPECT_EQ(validate(p)->field, "/timeScale");
}

}  // namespace
}  // namespace effects::lightning
