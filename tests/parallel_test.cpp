// effects/parallel.h: the pool covers every index exactly once, from many callers at once,
// and tangent frames are the same bit for bit whether the steps split or not.
#include <atomic>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <effects/parallel.h>
#include <effects/tangents.h>

namespace effects {
namespace {

TEST(ThreadPool, EveryIndexExactlyOnceFromManyCallersAtOnce) {
  ThreadPool pool(3);
  constexpr size_t kN = 100'003;
  std::vector<std::vector<std::atomic<int>>> hits(6);
  for (auto& h : hits) h = std::vector<std::atomic<int>>(kN);
  std::vector<std::thread> callers;
  std::atomic<int> chunksSeen{0};
  for (size_t c = 0; c < hits.size(); ++c)
    callers.emplace_back([&, c] {
      for (int round = 0; round < 5; ++round)
        pool.forRange(kN, 1000, [&](size_t begin, size_t end) {
          ASSERT_LT(begin, end);
          ++chunksSeen;
          for (size_t i = begin; i < end; ++i) ++hits[c][i];
        });
    });
  for (auto& t : callers) t.join();
  for (auto& h : hits)
    for (size_t i = 0; i < kN; ++i) ASSERT_EQ(h[i].load(), 5) << i;
  EXPECT_GT(chunksSeen.load(), int(hits.size() * 5)) << "the work was split";
}

TEST(ThreadPool, SmallRangesAndZeroWorkersRunOnTheCaller) {
  ThreadPool none(0);
  const auto caller = std::this_thread::get_id();
  int calls = 0;
  none.forRange(1'000'000, 10, [&](size_t b, size_t e) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    EXPECT_EQ(b, 0u);
    EXPECT_EQ(e, 1'000'000u);
    ++calls;
  });
  ThreadPool some(2);
  some.forRange(5, 10, [&](size_t b, size_t e) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    EXPECT_EQ(e - b, 5u);
    ++calls;
  });
  some.forRange(0, 10, [&](size_t, size_t) { ++calls; });
  forRange(nullptr, 0, 1, [&](size_t, size_t) { ++calls; });
  EXPECT_EQ(calls, 2);
}

// A 50k-triangle grid with wavy UVs: every mode, split over 3 workers or not, bit for bit.
TEST(ThreadPool, TangentsDoNotDependOnTheSplit) {
  tangents::Mesh m;
  const int n = 160;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      float x = float(i) / n, y = float(j) / n;
      m.positions.push_back({x, y, 0.1f * std::sin(9 * x) * std::cos(7 * y)});
      m.uvs.push_back({x + 0.05f * std::sin(13 * y), y});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
    }
  ThreadPool pool(3);
  for (auto mode : {tangents::Mode::kMikkTSpace, tangents::Mode::kPerTriangle, tangents::Mode::kPerVertex}) {
    tangents::Options serial;
    serial.mode = mode;
    serial.measureError = mode != tangents::Mode::kMikkTSpace;
    tangents::Options split = serial;
    split.parallel = &pool;
    auto a = tangents::generate(m, serial), b = tangents::generate(m, split);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(a.value().tangents.size(), b.value().tangents.size());
    EXPECT_EQ(std::memcmp(a.value().tangents.data(), b.value().tangents.data(),
                          a.value().tangents.size() * sizeof(glm::vec4)),
              0)
        << tangents::toString(mode);
    EXPECT_EQ(a.value().indices, b.value().indices);
    EXPECT_EQ(a.value().stats.error, b.value().stats.error);
  }
}

}  // namespace
}  // namespace effects
