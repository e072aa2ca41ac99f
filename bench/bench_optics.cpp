// Optics micro-benchmarks. Baseline: one paraxial y-nu trace through the lens; the other
// benchmarks are read as ratios against it in the same run (docs/performance.md).

#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/paraxial.h"
#include "optics/real_ray.h"

#include <benchmark/benchmark.h>

namespace {

using namespace ff;
using namespace ff::optics;

const Lens& zoomLens() {
    static const Lens lens = loadLens(std::string(FF_SOURCE_DIR) + "/lenses/zoom-70-200mm-f2.8.lens");
    return lens;
}

void BM_ParaxialTrace_Baseline(benchmark::State& state) {
    const Lens& lens = zoomLens();
    for (auto _ : state) benchmark::DoNotOptimize(traceParaxial(lens, lines::d, {1.0, 0.0}, 0, lens.surfaces.size()));
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ParaxialTrace_Baseline);

void BM_RealRayTrace(benchmark::State& state) {
    const Lens& lens = zoomLens();
    Ray ray{{0.0, 5.0, -1.0}, {0.0, 0.0, 1.0}};
    for (auto _ : state) benchmark::DoNotOptimize(traceReal(lens, lines::d, ray, true));
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RealRayTrace);

void BM_FirstOrderAnalysis(benchmark::State& state) {
    const Lens& lens = zoomLens();
    for (auto _ : state) benchmark::DoNotOptimize(analyzeFirstOrder(lens, lines::d));
}
BENCHMARK(BM_FirstOrderAnalysis);

void BM_LoadLensFile(benchmark::State& state) {
    for (auto _ : state)
        benchmark::DoNotOptimize(loadLens(std::string(FF_SOURCE_DIR) + "/lenses/zoom-70-200mm-f2.8.lens"));
}
BENCHMARK(BM_LoadLensFile);

} // namespace

BENCHMARK_MAIN();
