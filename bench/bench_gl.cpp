// The OpenGL backend (docs/gpu.md, docs/performance.md), on whatever EGL offers — a GPU, or llvmpipe:
//  - the bandwidth floor: a device-side copy of a buffer the size of the RGB float output; the floor
//    of an evaluation is output bytes / that bandwidth;
//  - evaluation of given coefficients with everything on the GPU (no read-back), 1920 x 1080 and
//    3840 x 2160 at N = 64, 128, 256, next to the CPU's matrix evaluation of the same coefficients;
//  - the whole GL render (accumulation + evaluation + read-back) against the number of ghosts K;
//  - the hybrid's direct drawing (GlDirect: axis integrals, then their products per pixel) of a few
//    frame-wide ghosts and of many small ones at 1280 x 720, next to fourier::drawDirect;
//  - the shaped ghosts' polygon raster against the CPU's coverage raster on 4 M small triangles;
//  - a shaped frame of the double Gauss at 1080p, 3 and 30 lights (300 on a GPU): meshes cut and
//    drawn on the CPU, cut on the CPU and drawn on the GPU, and both on the GPU (GlMeshCutter); and
//    what the host still does per frame on that last route (any machine, 300 lights too).
// On a software rasteriser only the 1080p, N = 64 and K <= 1000 cases run (the rest take minutes).

#include "fourier/direct.h"
#include "fourier/render.h"
#include "ghosts/ghost_table.h"
#include "gpu/gl_backend.h"
#include "gpu/gl_direct.h"
#include "gpu/gl_evaluator.h"
#include "gpu/gl_polygon_raster.h"
#include "optics/lens_loader.h"
#include "trace/flare_raster.h"

#include <benchmark/benchmark.h>
#include <epoxy/gl.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>

namespace {

using namespace ff::fourier;

struct Frame {
    int width, height;
};
constexpr Frame kFrames[] = {{1920, 1080}, {3840, 2160}};

ff::gpu::GlBackend* backend(std::string& why) {
    static std::string reason;
    static const std::shared_ptr<ff::gpu::GlBackend> gl = [] {
        auto context = ff::gpu::GlContext::create(reason);
        return context ? std::make_shared<ff::gpu::GlBackend>(std::move(context)) : nullptr;
    }();
    why = reason;
    return gl.get();
}

// The GL backend, or null after skipping the benchmark (no context; too slow on a software rasteriser).
ff::gpu::GlBackend* backendFor(benchmark::State& state, bool heavy) {
    std::string why;
    ff::gpu::GlBackend* gl = backend(why);
    if (!gl)
        state.SkipWithError(("no OpenGL 4.5 context: " + why).c_str());
    else if (heavy && !gl->context().hardware())
        state.SkipWithError("software rasteriser: skipped (minutes per iteration)");
    else
        state.SetLabel(gl->context().renderer());
    return gl && (!heavy || gl->context().hardware()) ? gl : nullptr;
}

std::vector<Ghost> ghosts(int K, int W, int H) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Ghost> g(static_cast<std::size_t>(K));
    for (Ghost& k : g) {
        k.x = u(rng) * W;
        k.y = u(rng) * H;
        const double s = (W / 64.0) * std::pow(4.0, u(rng)); // 30-120 px at 1080p
        for (int c = 0; c < 3; ++c) {
            k.widthX[c] = s * (1.0 + 0.05 * c);
            k.widthY[c] = s * (0.8 + 0.05 * c);
            k.flux[c] = u(rng);
        }
    }
    return g;
}

FourierSettings fixed(int n, const Frame& f) {
    FourierSettings s;
    s.fixedN = n;
    s.fixedPeriodX = f.width * 5.0 / 3.0;
    s.fixedPeriodY = f.height * 5.0 / 3.0;
    s.hybrid = false;
    return s;
}

Coefficients coefficientsAt(int n, const Frame& f) {
    const auto g = ghosts(100, f.width, f.height);
    const FourierSettings s = fixed(n, f);
    return accumulate(g, choosePlan(g, f.width, f.height, s), s);
}

// The time to copy a buffer of the output's size on the device (reads and writes it once): the floor
// an evaluation that writes the output is read against.
void BM_GlCopyFloor(benchmark::State& state) {
    const Frame f = kFrames[state.range(0)];
    ff::gpu::GlBackend* gl = backendFor(state, false);
    if (!gl) return;
    const std::size_t bytes = static_cast<std::size_t>(3) * f.width * f.height * sizeof(float);
    ff::gpu::Buffer a, b;
    a.zeros(bytes);
    b.zeros(bytes);
    glFinish();
    for (auto _ : state) {
        const auto t = std::chrono::steady_clock::now();
        glCopyNamedBufferSubData(a.id(), b.id(), 0, 0, static_cast<GLsizeiptr>(bytes));
        glFinish();
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    }
    state.counters["GB/s copied"] =
        benchmark::Counter(double(bytes) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_GlCopyFloor)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseManualTime();

// Evaluation with the coefficients and the image on the GPU (args: frame 0 = 1080p / 1 = 2160p, N).
void BM_GlEvaluate(benchmark::State& state) {
    const Frame f = kFrames[state.range(0)];
    const int n = static_cast<int>(state.range(1));
    ff::gpu::GlBackend* gl = backendFor(state, state.range(0) > 0 || n > 64);
    if (!gl) return;
    const Coefficients z = coefficientsAt(n, f);
    std::vector<float> zf;
    for (const auto& ch : z.z)
        for (double v : ch) zf.push_back(static_cast<float>(v));
    ff::gpu::Buffer zb, image;
    zb.upload(zf.data(), zf.size() * sizeof(float));
    image.zeros(static_cast<std::size_t>(3) * f.width * f.height * sizeof(float));
    ff::gpu::GlEvaluator evaluator(gl->context());
    evaluator.add(zb, z.n, z.m, z.periodX, z.periodY, f.width, f.height, image); // warm-up: compile, allocate
    glFinish();
    for (auto _ : state) {
        const auto t = std::chrono::steady_clock::now();
        evaluator.add(zb, z.n, z.m, z.periodX, z.periodY, f.width, f.height, image);
        glFinish();
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    }
    state.counters["M"] = z.m;
}
BENCHMARK(BM_GlEvaluate)->ArgsProduct({{0, 1}, {64, 128, 256}})->Unit(benchmark::kMillisecond)->UseManualTime();

// The CPU's matrix evaluation of the same coefficients, in the same run.
void BM_CpuEvaluate(benchmark::State& state) {
    const Frame f = kFrames[state.range(0)];
    const Coefficients z = coefficientsAt(static_cast<int>(state.range(1)), f);
    FlareImage image(f.width, f.height);
    for (auto _ : state) {
        evaluate(z, Evaluation::Matrix, image);
        benchmark::DoNotOptimize(image.channel[0].data());
    }
}
BENCHMARK(BM_CpuEvaluate)->ArgsProduct({{0, 1}, {64, 128, 256}})->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole GL render at 1080p, N = 64 (accumulation on the GPU, evaluation, read-back) against K.
void BM_GlRender(benchmark::State& state) {
    const Frame f = kFrames[0];
    const int K = static_cast<int>(state.range(0));
    ff::gpu::GlBackend* gl = backendFor(state, K > 1000);
    if (!gl) return;
    const auto g = ghosts(K, f.width, f.height);
    FourierSettings s = fixed(64, f);
    s.backend = std::shared_ptr<ff::gpu::GlBackend>(std::shared_ptr<ff::gpu::GlBackend>{}, gl); // not owned
    for (auto _ : state) {
        const FourierRender r = renderFourier(g, f.width, f.height, s);
        benchmark::DoNotOptimize(r.image.channel[0].data());
    }
}
BENCHMARK(BM_GlRender)->RangeMultiplier(10)->Range(100, 100000)->Unit(benchmark::kMillisecond)->UseRealTime();

// Direct-drawing scenes at 1280 x 720, both profiles mixed: 0 = 26 frame-wide ghosts (sigma 150-600
// px), 1 = 2 000 small ones (sigma 1-6 px), 2 = 104 of sigma 20-96 px (simulate's default plate draws
// 104 + 26 ghosts directly, of these two kinds).
std::vector<Ghost> directScene(int which) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int K = which == 0 ? 26 : which == 1 ? 2000 : 104;
    const double lo = which == 0 ? 150.0 : which == 1 ? 1.0 : 20.0, hi = which == 0 ? 600.0 : which == 1 ? 6.0 : 96.0;
    std::vector<Ghost> g(static_cast<std::size_t>(K));
    for (std::size_t k = 0; k < g.size(); ++k) {
        Ghost& q = g[k];
        q.shape = k % 2 ? Shape::Cos2 : Shape::Gaussian;
        q.x = u(rng) * 1280;
        q.y = u(rng) * 720;
        const double s = lo * std::pow(hi / lo, u(rng)) * (q.shape == Shape::Cos2 ? 2.5 : 1.0);
        for (int c = 0; c < 3; ++c) {
            q.widthX[c] = s * (1.0 + 0.05 * c);
            q.widthY[c] = s * (0.8 + 0.05 * c);
            q.flux[c] = u(rng);
        }
    }
    return g;
}

void BM_GlDirect(benchmark::State& state) {
    ff::gpu::GlBackend* gl = backendFor(state, false);
    if (!gl) return;
    const auto g = directScene(static_cast<int>(state.range(0)));
    std::vector<std::size_t> all(g.size());
    for (std::size_t k = 0; k < all.size(); ++k) all[k] = k;
    ff::gpu::GlDirect direct(gl->context());
    FlareImage image(1280, 720);
    for (auto _ : state) {
        direct.draw(g, all, image); // upload, draw, read back
        benchmark::DoNotOptimize(image.channel[0].data());
    }
}
BENCHMARK(BM_GlDirect)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CpuDirect(benchmark::State& state) {
    const auto g = directScene(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        const FlareImage image = renderDirect(g, 1280, 720);
        benchmark::DoNotOptimize(image.channel[0].data());
    }
}
BENCHMARK(BM_CpuDirect)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The shaped ghosts' polygon raster (gpu::GlPolygonRaster) against the CPU's coverage raster on the
// same polygons: n triangles of 0.3-3 px (the size the shaped renderer's subdivision makes) over a
// 1920 x 1080 frame, in 3 channels, with upload and read-back; the CPU draws them in one band on one
// thread (renderShaped spreads its bands over the cores). 4 M triangles on a GPU; 250 000 on any
// renderer, llvmpipe included (the CPU's cores running the same shaders).
std::vector<ff::ghosts::ShapedPolygons> triangles(int n) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<ff::ghosts::ShapedPolygons> out(3);
    for (int k = 0; k < n; ++k) {
        const glm::dvec2 c(1920.0 * u(rng), 1080.0 * u(rng));
        const double s = 0.3 + 2.7 * u(rng);
        const glm::dvec2 p[3] = {c, c + s * glm::dvec2(u(rng), 0.2 * u(rng)), c + s * glm::dvec2(0.2 * u(rng), u(rng))};
        out[static_cast<std::size_t>(k) % 3].add(p, 3, u(rng));
    }
    return out;
}

void BM_GlPolygons(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    ff::gpu::GlBackend* gl = backendFor(state, n > 1000000);
    if (!gl) return;
    const auto polys = triangles(n);
    const ff::trace::ImageFrame frame{1920, 1080, 0.01875};
    using Clock = std::chrono::steady_clock;
    double draw = 0.0, finish = 0.0;
    for (auto _ : state) {
        ff::gpu::GlPolygonRaster& raster = gl->polygonRaster();
        auto t = Clock::now();
        raster.begin(frame, 3, n);
        for (std::size_t c = 0; c < 3; ++c) raster.draw(c, polys[c]);
        glFinish();
        draw += std::chrono::duration<double>(Clock::now() - t).count();
        t = Clock::now();
        const auto image = raster.finish();
        finish += std::chrono::duration<double>(Clock::now() - t).count();
        benchmark::DoNotOptimize(image[0].data());
    }
    // draw: staging, uploads and the passes of the full batches; finish: the last batch, the image
    // pass and the read-back.
    state.counters["draw_ms"] = 1e3 * draw / double(state.iterations());
    state.counters["finish_ms"] = 1e3 * finish / double(state.iterations());
    state.counters["triangles/s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_GlPolygons)->Arg(250000)->Arg(4000000)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CpuPolygons(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const auto polys = triangles(n);
    const ff::trace::ImageFrame frame{1920, 1080, 0.01875};
    for (auto _ : state) {
        for (const auto& ps : polys) {
            ff::trace::CoverageRaster raster(frame);
            ff::trace::RasterStats stats;
            std::vector<glm::dvec2> p;
            for (const auto& q : ps.polys) {
                p.assign(ps.vertices.begin() + q.first, ps.vertices.begin() + q.first + q.count);
                raster.polygon(p, q.energy, stats);
            }
            const auto image = std::move(raster).release();
            benchmark::DoNotOptimize(image.data());
        }
    }
    state.counters["triangles/s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_CpuPolygons)->Arg(250000)->Arg(4000000)->Unit(benchmark::kMillisecond)->UseRealTime();

// A shaped frame: the bundled double Gauss's table (grid 32, 13 angles: built once, a few seconds),
// lights spread over a 1920 x 1080 frame (36 x 20.25 mm sensor), the renderer's default settings.
// Arg 0: the lights; arg 1: 0 CPU alone, 1 meshes cut on the CPU and drawn by the GL raster, 2 both on
// the GPU. Counters: triangles and instances per second.
const ff::ghosts::ShapedTable& doubleGauss() {
    static const ff::ghosts::ShapedTable table = [] {
        ff::ghosts::TableSettings s;
        s.grid = 32;
        s.angles = 13;
        // From the source tree this was built in, else from the working directory (a copy of the
        // repository on another machine).
        const std::filesystem::path built = std::filesystem::path(FF_SOURCE_DIR) / "lenses/double-gauss-50mm-f2.lens";
        const std::string path =
            std::filesystem::exists(built) ? built.string() : std::string("lenses/double-gauss-50mm-f2.lens");
        return ff::ghosts::buildShapedTable(ff::optics::loadLens(path), s);
    }();
    return table;
}

// n lights at random fields over the frame, random fluxes.
std::vector<ff::ghosts::ShapedLight> randomLights(const ff::ghosts::ShapedTable& table, int n) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<ff::ghosts::ShapedLight> ls(static_cast<std::size_t>(n));
    for (auto& l : ls) {
        l.field = {u(rng) * table.maxAngleDeg * std::numbers::pi / 180.0, 2.0 * std::numbers::pi * u(rng)};
        l.flux = {1.0 + u(rng), 1.0 + u(rng), 1.0 + u(rng)};
    }
    return ls;
}

void BM_ShapedFrame(benchmark::State& state) {
    const int lights = static_cast<int>(state.range(0)), route = static_cast<int>(state.range(1));
    // 300 lights only beside a GPU (the CPU's own case too: its baseline in the same run).
    ff::gpu::GlBackend* gl = backendFor(state, lights > 30);
    if (!gl) return;
    std::unique_ptr<ff::gpu::GlPolygonRaster> raster;
    if (route > 0)
        raster = std::make_unique<ff::gpu::GlPolygonRaster>(gl->context(), ff::gpu::GlPolygonRaster::kDefaultBatch,
                                                            ff::gpu::GlPolygonRaster::kDefaultListEntries, route == 2);
    const auto& table = doubleGauss();
    const ff::trace::ImageFrame frame{1920, 1080, 36.0 / 1920};
    const auto ls = randomLights(table, lights);
    std::size_t triangles = 0, drawn = 0;
    for (auto _ : state) {
        const auto out = ff::ghosts::renderShaped(table, ls, frame, {}, raster.get());
        triangles = out.triangles;
        drawn = out.drawn;
        benchmark::DoNotOptimize(out.channel[0].data());
    }
    state.counters["triangles/s"] =
        benchmark::Counter(double(triangles), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["instances"] = double(drawn);
}
BENCHMARK(BM_ShapedFrame)
    ->ArgsProduct({{3, 30, 300}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

// What the host still does per frame when the device cuts the meshes (the culling, each instance's
// tolerances from its mesh at one angle, the instances' list): renderShaped with a raster that takes
// the instances and draws nothing. Any machine; the same lights as BM_ShapedFrame.
class HostOnly final : public ff::ghosts::PolygonRaster {
  public:
    void begin(const ff::trace::ImageFrame& frame, std::size_t channels, double) override {
        pixels_ = static_cast<std::size_t>(frame.width) * frame.height;
        channels_ = channels;
    }
    void draw(std::size_t, const ff::ghosts::ShapedPolygons&) override {}
    std::vector<std::vector<double>> finish() override {
        return std::vector<std::vector<double>>(channels_, std::vector<double>(pixels_, 0.0));
    }
    bool cutsMeshes(const ff::ghosts::ShapedTable&) const override { return true; }
    std::vector<ff::ghosts::MeshDrawn> drawMeshes(const ff::ghosts::ShapedTable&,
                                                  const std::vector<ff::ghosts::MeshLight>&,
                                                  const std::vector<ff::ghosts::MeshDraw>& draws, std::size_t channels,
                                                  const ff::ghosts::ShapedRenderSettings&, float) override {
        return std::vector<ff::ghosts::MeshDrawn>(draws.size() * channels);
    }

  private:
    std::size_t pixels_ = 0, channels_ = 0;
};

void BM_ShapedFrameHost(benchmark::State& state) {
    const auto& table = doubleGauss();
    const ff::trace::ImageFrame frame{1920, 1080, 36.0 / 1920};
    const auto ls = randomLights(table, static_cast<int>(state.range(0)));
    HostOnly host;
    std::size_t drawn = 0;
    for (auto _ : state) {
        const auto out = ff::ghosts::renderShaped(table, ls, frame, {}, &host);
        drawn = out.drawn;
        benchmark::DoNotOptimize(out.channel[0].data());
    }
    state.counters["instances"] = double(drawn);
}
BENCHMARK(BM_ShapedFrameHost)->Arg(3)->Arg(30)->Arg(300)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
