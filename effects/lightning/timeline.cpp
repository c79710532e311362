// The strike timeline: stepped leader, return strokes, flicker and fade (lightning.h).
// Computed in physical seconds, scaled to game seconds at the end.
#include <algorithm>
#include <cmath>
#include <string>

#include "effects/lightning.h"

namespace effects::lightning {
namespace {

constexpr double kRiseS = 20e-6;      // a stroke's flash reaches its peak (current rise ~ microseconds)
constexpr double kFlickerS = 4e-3;    // spacing of the flicker noise's lattice
constexpr double kFlashShare = 0.75;  // of a stroke's peak: the flash; the rest is the channel's glow
constexpr double kDarkLevel = 0.004;  // the glow is over below this

// A uniform in [0, 1) from (seed, a, b): independent of evaluation order.
double hashUniform(uint64_t seed, uint64_t a, uint64_t b) {
  Rng r(seed ^ (0x9E3779B97F4A7C15ULL * (a + 1)) ^ (0xC2B2AE3D27D4EB4FULL * (b + 1)), 0x632BE59BD9B4E019ULL);
  return r.uniform();
}

// The physical strike: channel brightness as functions of time.
struct Strike {
  TimelineParams p;
  double leaderEnd = 0;  // the leader glows until the slowest stroke front has passed
  std::vector<Stroke> strokes;

  // Value noise in [1 - flicker, 1 + flicker], linear between lattice points.
  double flick(double t) const {
    const double x = std::max(0.0, t) / kFlickerS, f = std::floor(x);
    const auto i = uint64_t(f);
    const double a = hashUniform(p.seed, 7, i), b = hashUniform(p.seed, 7, i + 1);
    return 1 + p.flicker * (2 * (a + (b - a) * (x - f)) - 1);
  }
  // A stroke's light: rising over kRiseS to its peak, then decaying with time constant decayMs.
  static double pulse(const Stroke& s, double t, double decayMs) {
    if (t < s.t) return 0;
    return s.peak * std::min(1.0, (t - s.t) / kRiseS) * std::exp(-(t - s.t) / (decayMs * 1e-3));
  }
  Keyframe at(double t) const {
    Keyframe k;
    k.t = t;
    k.leader = float(t < leaderEnd ? p.leaderBrightness : 0.0);
    double main = 0;
    for (const Stroke& s : strokes)
      main += kFlashShare * pulse(s, t, p.flashMs) + (1 - kFlashShare) * pulse(s, t, p.glowMs) * flick(t);
    k.main = float(std::min(1.0, main));
    k.branches = float(kFlashShare * pulse(strokes.front(), t, p.flashMs));
    return k;
  }
};

// Leader arrival and stroke delay per bolt node, in physical seconds.
void nodeTimes(const Bolt& bolt, const TimelineParams& p, std::vector<double>& leader, std::vector<double>& delay) {
  const size_t n = bolt.nodes.size();
  std::vector<double> length(n, 0.0);  // path length from the start, metres
  leader.assign(n, 0.0);
  for (size_t i = 1; i < n; ++i) {  // growth order: parents first
    const Node& nd = bolt.nodes[i];
    const size_t parent = size_t(nd.parent);
    const Cell a = bolt.nodes[parent].cell;
    const double dx = nd.cell.x - a.x, dy = nd.cell.y - a.y, dz = nd.cell.z - a.z;
    length[i] = length[parent] + p.cellSize * (dz != 0 ? std::hypot(dx, dy, dz) : std::hypot(dx, dy));
    // The leader jumps a whole step at a time: a vertex lights with the step that covers it.
    const auto from = uint64_t(length[parent] / p.leaderStep), to = uint64_t(length[i] / p.leaderStep);
    leader[i] = leader[parent];
    if (to - from > 64)  // a cell many steps long: the pauses' mean (the sum of many uniforms)
      leader[i] += 1e-6 * double(to - from) * 0.5 * (p.pauseMinUs + p.pauseMaxUs);
    else
      for (uint64_t s = from + 1; s <= to; ++s)
        leader[i] += 1e-6 * (p.pauseMinUs + (p.pauseMaxUs - p.pauseMinUs) * hashUniform(p.seed, i, s));
  }
  // The return stroke runs from the channel's end back up the main channel and out along the
  // branches (current flows from the branches into the channel).
  delay.assign(n, -1.0);
  const double total = length[size_t(bolt.mainChannel.back())];
  for (int m : bolt.mainChannel) delay[size_t(m)] = (total - length[size_t(m)]) / p.returnStrokeSpeed;
  for (size_t i = 1; i < n; ++i)
    if (delay[i] < 0) {
      const size_t parent = size_t(bolt.nodes[i].parent);
      delay[i] = delay[parent] + (length[i] - length[parent]) / p.returnStrokeSpeed;
    }
  if (delay[0] < 0) delay[0] = 0;
}

std::vector<Stroke> strokesOf(const TimelineParams& p, double connect) {
  const int count = p.strokes > 0 ? p.strokes : 3 + (hashUniform(p.seed, 1, 0) < 0.5 ? 1 : 0);
  std::vector<Stroke> out;
  double t = connect;
  for (int k = 0; k < count; ++k) {
    if (k) t += 1e-3 * (p.intervalMinMs + (p.intervalMaxMs - p.intervalMinMs) * hashUniform(p.seed, 2, uint64_t(k)));
    out.push_back({t, k ? float(0.5 + 0.35 * hashUniform(p.seed, 3, uint64_t(k))) : 1.0f});
  }
  return out;
}

// Sample times that catch every corner of the channel functions: the leader's end, each
// stroke's start and peak, its flash decay, the flicker lattice, the fade.
std::vector<double> sampleTimes(const Strike& s, double end) {
  std::vector<double> t{0.0, s.leaderEnd, s.leaderEnd + 1e-6};
  const double flash = s.p.flashMs * 1e-3;
  for (size_t k = 0; k < s.strokes.size(); ++k) {
    const double t0 = s.strokes[k].t, t1 = k + 1 < s.strokes.size() ? s.strokes[k + 1].t : end;
    t.push_back(t0);
    t.push_back(t0 + kRiseS);
    for (double f : {0.25, 0.5, 1.0, 2.0, 3.0})
      if (t0 + f * flash < t1) t.push_back(t0 + f * flash);
    for (double x = std::ceil(t0 / kFlickerS) * kFlickerS; x < t1; x += kFlickerS) t.push_back(x);
  }
  t.push_back(end);
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end(), [](double a, double b) { return b - a < 1e-9; }), t.end());
  return t;
}

// The first keyframe after t.
std::vector<Keyframe>::const_iterator after(const Timeline& tl, double t) {
  return std::upper_bound(tl.keyframes.begin(), tl.keyframes.end(), t,
                          [](double x, const Keyframe& f) { return x < f.t; });
}

// The highest value of one channel (piecewise linear between keyframes) over [a, b]: its ends
// and the keyframes inside (found by bisection: a frame holds a handful of them).
double peak(const Timeline& tl, float Keyframe::*channel, double a, double b) {
  if (b < a) return 0;
  double best = std::max(channelsAt(tl, a).*channel, channelsAt(tl, b).*channel);
  for (auto it = after(tl, a); it != tl.keyframes.end() && it->t < b; ++it)
    best = std::max(best, double((*it).*channel));
  return best;
}

}  // namespace

std::optional<Error> validate(const TimelineParams& p) {
  if (!(p.timeScale > 0 && p.timeScale <= 1e6)) return invalid("/timeScale", "must be in (0, 1e6]");
  if (!(p.cellSize > 0 && p.cellSize <= 1e4)) return invalid("/timeline/cellSize", "must be in (0, 1e4] metres");
  if (!(p.leaderStep >= 1 && p.leaderStep <= 1e4)) return invalid("/timeline/leaderStep", "must be in [1, 1e4] metres");
  if (!(p.pauseMinUs > 0 && p.pauseMaxUs >= p.pauseMinUs && p.pauseMaxUs <= 1e6))
    return invalid("/timeline/leaderPause", "must be [min, max] microseconds with 0 < min <= max <= 1e6");
  if (!(p.returnStrokeSpeed >= 1e5 && p.returnStrokeSpeed <= 3e8))
    return invalid("/timeline/returnStrokeSpeed", "must be in [1e5, 3e8] m/s");
  if (p.strokes < 0 || p.strokes > 64) return invalid("/timeline/strokes", "must be in [0, 64]");
  if (!(p.intervalMinMs > 0 && p.intervalMaxMs >= p.intervalMinMs && p.intervalMaxMs <= 1e4))
    return invalid("/timeline/strokeInterval", "must be [min, max] milliseconds with 0 < min <= max <= 1e4");
  if (!(p.flashMs > 0 && p.flashMs <= 1e4)) return invalid("/timeline/flashDecay", "must be in (0, 1e4] milliseconds");
  if (!(p.glowMs > 0 && p.glowMs <= 1e4)) return invalid("/timeline/glowDecay", "must be in (0, 1e4] milliseconds");
  if (!(p.leaderBrightness >= 0 && p.leaderBrightness <= 1))
    return invalid("/timeline/leaderBrightness", "must be in [0, 1]");
  if (!(p.flicker >= 0 && p.flicker <= 1)) return invalid("/timeline/flicker", "must be in [0, 1]");
  return std::nullopt;
}

namespace {

// What timeline() relies on: the bolt in growth order (every node after its parent), a main
// channel of its nodes, polylines of its nodes.
std::optional<Error> checkBolt(const Bolt& bolt, const std::vector<Polyline>& lines) {
  const size_t n = bolt.nodes.size();
  if (n == 0 || bolt.mainChannel.empty()) return invalid("/bolt", "has no nodes or no main channel: grow() makes one");
  if (bolt.nodes[0].parent != -1) return invalid("/bolt", "node 0 must be the start (parent -1)");
  for (size_t i = 1; i < n; ++i)
    if (bolt.nodes[i].parent < 0 || size_t(bolt.nodes[i].parent) >= i)
      return invalid("/bolt", "node " + std::to_string(i) + "'s parent must come before it (growth order)");
  for (int m : bolt.mainChannel)
    if (m < 0 || size_t(m) >= n) return invalid("/bolt", "the main channel names node " + std::to_string(m) + " of " + std::to_string(n));
  for (const Polyline& l : lines)
    for (const Vertex& v : l.vertices)
      if (v.node < 0 || size_t(v.node) >= n)
        return invalid("/lines", "a vertex names node " + std::to_string(v.node) + " of a bolt of " + std::to_string(n) +
                                     ": polylines of another bolt");
  return std::nullopt;
}

}  // namespace

Result<Timeline> timeline(const Bolt& bolt, const std::vector<Polyline>& lines, const TimelineParams& p) {
  if (auto e = validate(p)) return *e;
  if (auto e = checkBolt(bolt, lines)) return *e;
  std::vector<double> leader, delay;
  nodeTimes(bolt, p, leader, delay);
  Strike s;
  s.p = p;
  const double connect = leader[size_t(bolt.mainChannel.back())];
  const double maxDelay = *std::max_element(delay.begin(), delay.end());
  s.leaderEnd = connect + maxDelay;
  s.strokes = strokesOf(p, connect);
  // The channels go dark after the last stroke's glow; the farthest vertex sees that maxDelay
  // later (a slow stroke on a long channel), and the leader's glow may outlast both.
  const double end =
      std::max(s.strokes.back().t + p.glowMs * 1e-3 * std::log(1 / kDarkLevel), s.leaderEnd + 1e-6) + maxDelay;

  Timeline tl;
  const double k = p.timeScale;
  for (double t : sampleTimes(s, end)) {
    Keyframe f = s.at(t);
    f.t = t * k;
    tl.keyframes.push_back(f);
  }
  tl.keyframes.back().main = tl.keyframes.back().branches = tl.keyframes.back().leader = 0;
  for (Stroke st : s.strokes) tl.strokes.push_back({st.t * k, st.peak});
  tl.connect = connect * k;
  tl.duration = end * k;
  for (const Polyline& l : lines) {
    std::vector<double> a, d;
    for (const Vertex& v : l.vertices) {
      a.push_back(leader[size_t(v.node)] * k);
      d.push_back(delay[size_t(v.node)] * k);
    }
    tl.leader.push_back(std::move(a));
    tl.strokeDelay.push_back(std::move(d));
  }
  return tl;
}

Keyframe channelsAt(const Timeline& tl, double t) {
  const auto& k = tl.keyframes;
  Keyframe out;
  out.t = t;
  if (k.empty() || t < k.front().t || t > k.back().t) return out;
  auto it = after(tl, t);
  if (it == k.end()) return k.back();
  const Keyframe& b = *it;
  const Keyframe& a = *(it - 1);
  const double w = b.t > a.t ? (t - a.t) / (b.t - a.t) : 1.0;
  out.leader = float(a.leader + (b.leader - a.leader) * w);
  out.main = float(a.main + (b.main - a.main) * w);
  out.branches = float(a.branches + (b.branches - a.branches) * w);
  return out;
}

double vertexBrightness(const Timeline& tl, const std::vector<Polyline>& lines, size_t line, size_t vertex, double t) {
  const double arrive = tl.leader[line][vertex], delay = tl.strokeDelay[line][vertex];
  if (arrive > tl.connect || t < arrive) return 0;
  const Vertex& v = lines[line].vertices[vertex];
  if (t < tl.connect + delay) return v.intensity * channelsAt(tl, t).leader;
  const Keyframe c = channelsAt(tl, t - delay);
  return v.intensity * (lines[line].main ? c.main : c.branches);
}

std::vector<Polyline> exposure(const Timeline& tl, const std::vector<Polyline>& lines, double t0, double t1) {
  std::vector<Polyline> out;
  for (size_t i = 0; i < lines.size(); ++i) {
    Polyline cut;  // the line's channel and width, its vertices as far as the leader came
    cut.main = lines[i].main;
    cut.width = lines[i].width;
    bool lit = false;
    for (size_t j = 0; j < lines[i].vertices.size(); ++j) {
      const double arrive = tl.leader[i][j], delay = tl.strokeDelay[i][j];
      if (arrive > tl.connect || arrive > t1) break;  // leader times grow along the line
      Vertex v = lines[i].vertices[j];
      const double from = std::max(t0, arrive), stroke = tl.connect + delay;
      const double leaderPart = from < stroke ? peak(tl, &Keyframe::leader, from, std::min(t1, stroke)) : 0.0;
      const double strokePart = t1 >= stroke ? peak(tl, lines[i].main ? &Keyframe::main : &Keyframe::branches,
                                                    std::max(from, stroke) - delay, t1 - delay)
                                             : 0.0;
      const double b = v.intensity * std::max(leaderPart, strokePart);
      v.intensity = float(b);
      lit = lit || b > 0;
      cut.vertices.push_back(v);
    }
    if (lit && cut.vertices.size() >= 2) out.push_back(std::move(cut));
  }
  return out;
}

}  // namespace effects::lightning
