// Fog tables: time to build a 4096-entry table per mode (target <= 100 us), and the
// interpolation error against size (printed as counters: maxError).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

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
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7, 8}, {16, 64, 256, 1024, 4096}})
    ->Unit(benchmark::kMicrosecond);

// The baseline for height fog: the same 2048 x 2 table filled entry by entry from the closed
// form (heightOpticalDepth, in log space), as tables were built before the row recurrence.
void BM_HeightTableClosedFormPerEntry(benchmark::State& state) {
  Fog f = fixtures::fogOf(FogType::kHeight);
  TableOptions o;
  o.size = size_t(state.range(0)) / 2;
  o.elevations = 2;
  o.measureError = false;
  const Table shape = buildTable(f, o).value();
  std::vector<float> out(shape.factor.size());
  for (auto _ : state) {
    for (size_t j = 0; j < shape.height; ++j) {
      const double dirY = -1.0 + 2.0 * double(j) / double(shape.height - 1);
      for (size_t i = 0; i < shape.width; ++i) {
        const double d = shape.rangeStart + (shape.rangeEnd - shape.rangeStart) * double(i) / double(shape.width - 1);
        out[j * shape.width + i] =
            float(std::exp(-heightOpticalDepth(f.density, f.heightFalloff, f.baseHeight, o.cameraHeight, dirY, d)));
      }
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetLabel("HEIGHT closed form per entry");
}
BENCHMARK(BM_HeightTableClosedFormPerEntry)->Arg(4096)->Unit(benchmark::kMicrosecond);

}  // namespace
