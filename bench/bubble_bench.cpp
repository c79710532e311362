// Bubble figures of issue 6: building a level-5 icosphere response (mesh + MikkTSpace frames +
// per-vertex final vectors) and the 256 x 256 thin-film table at each wavelength sampling,
// with its Delta E against the 1 nm reference (counters meanDeltaE, maxDeltaE).
#include <benchmark/benchmark.h>


#include <effects/bubble.h>

namespace {

using namespace effects::bubble;

void BM_Icosphere(benchmark::State& state) {
  MeshOptions o;
  o.level = int(state.range(0));
  o.t = 12.5;
  o.camera = glm::dvec3(0, 0, 4);
  static effects::ThreadPool pool(effects::ThreadPool::besideCaller());  // as effectd runs it
  o.parallel = &pool;
  size_t vertices = 0;
  for (auto _ : state) {
    auto r = icosphere(Params{}, o);
    vertices = r.value().positions.size();
    benchmark::DoNotOptimize(r.value().positions.data());
  }
  state.counters["vertices"] = double(vertices);
}

void BM_ThinFilm256(benchmark::State& state) {
  ThinFilmOptions o;
  o.wavelengths = int(state.range(0));
  o.measureError = false;  // timed without the reference
  for (auto _ : state) benchmark::DoNotOptimize(thinFilmTable(o).value().rgb.data());
  o.measureError = true;
  auto t = thinFilmTable(o);
  state.counters["meanDeltaE"] = t.value().meanDeltaE;
  state.counters["maxDeltaE"] = t.value().maxDeltaE;
}

BENCHMARK(BM_Icosphere)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ThinFilm256)->Arg(3)->Arg(8)->Arg(16)->Arg(32)->Arg(81)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
