// Tangent figures of issue 5: a 100k-triangle mesh (UV sphere 250 x 200 segments, seam and
// poles included, normals given) in each mode (target: MikkTSpace <= 30 ms), and the
// per-triangle mode's angle error against MikkTSpace on the same mesh, printed as counters
// (meanAngleDeg, maxAngleDeg) for the error-against-run-time report. Its peer, the reference
// algorithm as npm's WebAssembly build, is bench/mikktspace_peer.mjs (scripts/bench-table.py
// runs both).
#include <benchmark/benchmark.h>

#include <cmath>

#include <effects/tangents.h>

#include "fixtures.h"

namespace {

using namespace effects::tangents;

const Mesh& mesh100k() {
  static const Mesh m = fixtures::uvSphere(200, 250);  // 99 500 triangles
  return m;
}

// As effectd runs it: the steps split over a pool of cores - 1 workers beside the caller.
effects::ThreadPool& pool() {
  static effects::ThreadPool p(effects::ThreadPool::besideCaller());
  return p;
}

void run(benchmark::State& state, Mode mode, bool measure, bool oneThread = false) {
  Options o;
  o.mode = mode;
  o.measureError = measure;
  o.parallel = oneThread ? nullptr : &pool();
  effects::Stats last;
  for (auto _ : state) {
    auto r = generate(mesh100k(), o);
    if (!r.ok()) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    last = r.value().stats;
    benchmark::DoNotOptimize(r.value().tangents.data());
  }
  double tris = double(mesh100k().indices.size() / 3);
  state.counters["triangles"] = tris;
  state.counters["poolThreads"] = oneThread ? 1.0 : double(pool().threads() + 1);
  state.counters["tris_per_s"] = benchmark::Counter(tris * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["outVertices"] = last.counters["outputVertices"];
  if (last.error) {
    state.counters["meanAngleDeg"] = *last.error;
    state.counters["maxAngleDeg"] = last.counters["maxAngleDeg"];
  }
}

void BM_MikkTSpace100k(benchmark::State& s) { run(s, Mode::kMikkTSpace, false); }
void BM_MikkTSpace100kOneThread(benchmark::State& s) { run(s, Mode::kMikkTSpace, false, true); }
void BM_PerTriangle100k(benchmark::State& s) { run(s, Mode::kPerTriangle, false); }
void BM_PerTriangleErrorVsMikk100k(benchmark::State& s) { run(s, Mode::kPerTriangle, true); }

BENCHMARK(BM_MikkTSpace100k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MikkTSpace100kOneThread)->Unit(benchmark::kMillisecond);  // as the peer runs
BENCHMARK(BM_PerTriangle100k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PerTriangleErrorVsMikk100k)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
