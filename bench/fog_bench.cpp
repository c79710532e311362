// Fog tables: time to build a 4096-entry table per mode (target <= 100 us), and the
// interpolation error against size (printed as counters: maxError).
#include <benchmark/benchmark.h>

#include <effects/fog.h>

#include "fixtures.h"

namespace {

using namespace effects::fog;

void BM_FogTable(benchmark::State& state) {
  Fog f = fixtures::fogOf(static_cast<FogType>(state.range(0)));
  TableOptions o;
  // Height fog tables are 2-D: N/2 distances x 2 elevations keeps the entry count at N.
  const bool twoD = f.type == FogType::kHeight;
  o.size = size_t(state.range(1)) / (twoD ? 2 : 1);
  o.elevations = twoD ? 2 : 0;
  o.measureError = false;
  for (auto _ : state) {
    auto t = buildTable(f, o);
    benchmark::DoNotOptimize(t.value().factor.data());
  }
  o.measureError = true;
  state.counters["maxError"] = buildTable(f, o).value().maxError;
  state.SetLabel(toString(f.type));
}
BENCHMARK(BM_FogTable)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7}, {16, 64, 256, 1024, 4096}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
