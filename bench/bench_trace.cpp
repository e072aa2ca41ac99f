// Tracing benchmarks: rays per second along the direct path and along all two-bounce ghost paths,
// Embree packets versus the analytic loop, on 1 and 2 threads. Baseline: the analytic loop on one
// thread for the same lens and paths; read the others as ratios against it (docs/performance.md).

#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/lens_parser.h"
#include "trace/embree_tracer.h"
#include "trace/ghost_analysis.h"
#include "trace/pupil_sampling.h"
#include "trace/traced_flare.h"

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <map>

namespace {

using namespace ff;
using namespace ff::trace;

struct Workload {
    optics::Lens lens;
    std::unique_ptr<LensAtWavelength> L;
    std::unique_ptr<EmbreeTracer> tracer;
    Bundle bundle;
    std::vector<std::vector<PathStep>> direct, ghosts;
};

// A bundled lens file's workload, or (text given) that of a lens written out here.
Workload& workload(const std::string& file, int grid, const char* text = nullptr) {
    static std::map<std::string, std::unique_ptr<Workload>> cache;
    auto& w = cache[file + std::to_string(grid)];
    if (!w) {
        w = std::make_unique<Workload>();
        w->lens =
            text ? optics::parseLensText(text, file) : optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/" + file);
        w->L = std::make_unique<LensAtWavelength>(w->lens, 550.0);
        w->tracer = std::make_unique<EmbreeTracer>(*w->L);
        const PupilFrame f = pupilFrame(w->lens);
        w->bundle = gridBundle(f, {degToRad(10.0), 0.0}, grid, 0.0, 0.0, f.radius, true);
        w->direct.push_back(pathSteps(w->lens, std::nullopt));
        for (const GhostPair& g : enumerateGhosts(w->lens)) w->ghosts.push_back(pathSteps(w->lens, g));
    }
    return *w;
}

template <bool UseEmbree, bool Ghosts>
void traceRays(benchmark::State& state, const char* file, int grid, const char* text = nullptr) {
    Workload& w = workload(file, grid, text);
    const auto& paths = Ghosts ? w.ghosts : w.direct;
    std::vector<RayResult> out(w.bundle.rays.size());
    tbb::task_arena arena(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        arena.execute([&] {
            for (const auto& steps : paths) {
                if constexpr (UseEmbree)
                    w.tracer->trace(*w.L, steps, w.bundle.rays, out);
                else
                    traceAnalytic(*w.L, steps, w.bundle.rays, out);
            }
        });
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * paths.size() * w.bundle.rays.size()));
}

void BM_DoubleGauss_Direct_Analytic_Baseline(benchmark::State& s) {
    traceRays<false, false>(s, "double-gauss-50mm-f2.lens", 64);
}
void BM_DoubleGauss_Direct_Embree(benchmark::State& s) {
    traceRays<true, false>(s, "double-gauss-50mm-f2.lens", 64);
}
void BM_DoubleGauss_Ghosts_Analytic(benchmark::State& s) {
    traceRays<false, true>(s, "double-gauss-50mm-f2.lens", 64);
}
void BM_DoubleGauss_Ghosts_Embree(benchmark::State& s) {
    traceRays<true, true>(s, "double-gauss-50mm-f2.lens", 64);
}
void BM_Zoom_Direct_Analytic(benchmark::State& s) {
    traceRays<false, false>(s, "zoom-70-200mm-f2.8.lens", 64);
}
void BM_Zoom_Direct_Embree(benchmark::State& s) {
    traceRays<true, false>(s, "zoom-70-200mm-f2.8.lens", 64);
}
void BM_Zoom_Ghosts_Analytic(benchmark::State& s) {
    traceRays<false, true>(s, "zoom-70-200mm-f2.8.lens", 16);
}
void BM_Zoom_Ghosts_Embree(benchmark::State& s) {
    traceRays<true, true>(s, "zoom-70-200mm-f2.8.lens", 16);
}
BENCHMARK(BM_DoubleGauss_Direct_Analytic_Baseline)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DoubleGauss_Direct_Embree)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DoubleGauss_Ghosts_Analytic)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DoubleGauss_Ghosts_Embree)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Zoom_Direct_Analytic)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Zoom_Direct_Embree)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Zoom_Ghosts_Analytic)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Zoom_Ghosts_Embree)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// A ray through a graded element (RK4 at the default tolerance, 1e-9 mm per mm of path) against the
// same element as homogeneous glass: a singlet (40 / -60 mm, 6 mm thick, n0 = 1.6) behind a stop, with
// the radial and axial gradient of docs/grin.md's end-to-end example or without it; its direct path
// (through the element once) and its 3 ghosts (through it once or three times), one thread, 64 x 64
// rays at 10 degrees. The lens is the element: the ratio of the times is the cost per element.
constexpr const char* kGradedSinglet =
    "f_number: 4\nsurfaces:\n  stop 3 1 0 6\n  40 6 1.6 40 8 1 grin_r=-0.002:1e-05 grin_z=0.004:0\n"
    "  -60 auto air 8 1\n";
constexpr const char* kHomogeneousSinglet = "f_number: 4\nsurfaces:\n  stop 3 1 0 6\n  40 6 1.6 40 8 1\n"
                                            "  -60 auto air 8 1\n";
void BM_Singlet_Direct_Homogeneous_Baseline(benchmark::State& s) {
    traceRays<false, false>(s, "homogeneous.lens", 64, kHomogeneousSinglet);
}
void BM_Singlet_Direct_Graded(benchmark::State& s) {
    traceRays<false, false>(s, "graded.lens", 64, kGradedSinglet);
}
void BM_Singlet_Ghosts_Homogeneous(benchmark::State& s) {
    traceRays<false, true>(s, "homogeneous.lens", 64, kHomogeneousSinglet);
}
void BM_Singlet_Ghosts_Graded(benchmark::State& s) {
    traceRays<false, true>(s, "graded.lens", 64, kGradedSinglet);
}
BENCHMARK(BM_Singlet_Direct_Homogeneous_Baseline)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Singlet_Direct_Graded)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Singlet_Ghosts_Homogeneous)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Singlet_Ghosts_Graded)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The target: every ghost of the double Gauss at one angle, 3 wavelengths, 64 x 64 grid
// (re-aimed pupils, statistics included), i.e. what 'fourierflare ghosts' does.
void BM_DoubleGauss_GhostReport_3Wavelengths(benchmark::State& state) {
    const optics::Lens lens = optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/double-gauss-50mm-f2.lens");
    GhostAnalysisOptions o;
    o.field = {degToRad(10.0), 0.0};
    o.wavelengthsNm = {450.0, 550.0, 650.0};
    tbb::task_arena arena(static_cast<int>(state.range(0)));
    for (auto _ : state) arena.execute([&] { benchmark::DoNotOptimize(analyzeGhosts(lens, o)); });
}
BENCHMARK(BM_DoubleGauss_GhostReport_3Wavelengths)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

// The traced flare of the double Gauss at 1920 x 1080, one light at pixel (1500, 200), 450/550/650
// nm: the adaptive default (32 x 32 starting grids, refined) against the baseline, the renderer
// before adaptive refinement (a 64 x 64 grid per ghost, drawn as it is).
void tracedFlare(benchmark::State& state, int grid, bool adaptive) {
    static const optics::Lens lens = optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/double-gauss-50mm-f2.lens");
    TracedFlareOptions o;
    o.frame = {1920, 1080, 36.0 / 1920};
    const glm::dvec2 s = o.frame.pixelToSensor(1500.0, 200.0);
    o.field = fieldForSensorPoint(lens, sensorPlaneZ(lens, o.sensor), s.x, s.y);
    o.grid = grid;
    o.adaptive = adaptive;
    std::size_t rays = 0;
    for (auto _ : state) rays = renderTracedFlare(lens, o).samples;
    state.counters["rays"] = static_cast<double>(rays);
}
void BM_TracedFlare_DoubleGauss1080p_Baseline_Unrefined64(benchmark::State& state) {
    tracedFlare(state, 64, false);
}
void BM_TracedFlare_DoubleGauss1080p_Adaptive(benchmark::State& state) {
    tracedFlare(state, 32, true);
}
BENCHMARK(BM_TracedFlare_DoubleGauss1080p_Baseline_Unrefined64)->Iterations(2)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_TracedFlare_DoubleGauss1080p_Adaptive)->Iterations(2)->Unit(benchmark::kSecond)->UseRealTime();

BENCHMARK_MAIN();
