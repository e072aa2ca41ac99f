// `simulate` per frame at 1920 x 1080 with 3, 30 and 300 lights (the double Gauss, the main job's
// lens): the stages as the command runs them — read the plate, find the lights, draw the flare, write
// the EXR — with the shaped ghosts (the default) and with the fitted Gaussians aggregated through
// Fourier (BM_SimulateCached). Baseline: the 3-light frame with the tables in memory. The tables'
// own costs: building them (BM_SimulateUncached, BM_ShapedTableBuild) and loading the shaped one
// from its cache entry (BM_ShapedTableLoad).

#include "fourier/render.h"
#include "ghosts/ghost_table.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_cache.h"
#include "ghosts/shaped_ghosts.h"
#include "gpu/gl_polygon_raster.h"
#include "image/composite.h"
#include "image/image_output.h"
#include "image/light_detection.h"
#include "image/plate.h"
#include "optics/lens_loader.h"
#include "scene/scene.h"

#include <OpenImageIO/imageio.h>
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>

#include "bench_plates.h"
#include "gl_bench.h"

namespace {

using namespace ff;
constexpr int kW = bench::kPlateWidth, kH = bench::kPlateHeight;

std::string plateWith(int lights) {
    const auto path = std::filesystem::temp_directory_path() / ("ff-bench-plate-" + std::to_string(lights) + ".exr");
    if (std::filesystem::exists(path)) return path.string();
    const std::vector<float> px = bench::platePixels(lights);
    OIIO::ImageSpec spec(kW, kH, 3, OIIO::TypeDesc::HALF);
    spec.attribute("compression", "zip");
    auto out = OIIO::ImageOutput::create(path.string());
    out->open(path.string(), spec);
    out->write_image(OIIO::TypeDesc::FLOAT, px.data());
    out->close();
    return path.string();
}

const optics::Lens& lens() {
    static const optics::Lens l = optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/double-gauss-50mm-f2.lens");
    return l;
}

const ghosts::GhostTable& cachedTable() {
    static const ghosts::GhostTable t = ghosts::buildGhostTable(lens(), ghosts::TableSettings{});
    return t;
}

// The shaped table for the bench's 16:9 sensor, 36 mm wide, as a run stores and loads it.
const std::string& shapedBytes() {
    static const std::string bytes = [] {
        ghosts::TableSettings s;
        s.sensorSizeMm = {36.0, 36.0 * kH / kW};
        return ghosts::shapedTableToBytes(ghosts::buildShapedTable(lens(), s), "bench");
    }();
    return bytes;
}

const ghosts::ShapedTable& shapedTable() {
    static const ghosts::ShapedTable t = [] {
        std::string key;
        return ghosts::shapedTableFromBytes(shapedBytes(), "bench", key);
    }();
    return t;
}

// One frame's stages per iteration, timed; `draw` makes the flare of the plate's lights.
void frame(benchmark::State& state, const std::string& platePath,
           const std::function<fourier::FlareImage(const std::vector<ghosts::Light>&)>& draw) {
    using Clock = std::chrono::steady_clock;
    double read = 0, detect = 0, flare = 0, write = 0;
    const auto out = std::filesystem::temp_directory_path() / "ff-bench-out.exr";
    auto lap = [](Clock::time_point& t) {
        const auto now = Clock::now();
        const double s = std::chrono::duration<double>(now - t).count();
        t = now;
        return s;
    };
    for (auto _ : state) {
        auto t = Clock::now();
        const image::Plate plate = image::readPlate(platePath);
        read += lap(t);
        const image::DetectionReport found = image::detectLights(plate, {});
        std::vector<ghosts::Light> lights;
        for (const auto& l : found.lights) lights.push_back({l.x, l.y, l.flux});
        detect += lap(t);
        const std::vector<float> layer = draw(lights).interleaved();
        flare += lap(t);
        const std::vector<float> composite = image::composite(plate.rgb(), layer);
        image::writeSimulatedExr(out.string(), plate, {{"flare", &layer}, {"composite", &composite}}, {});
        write += lap(t);
    }
    const double n = double(state.iterations());
    state.counters["read_ms"] = 1e3 * read / n;
    state.counters["detect_ms"] = 1e3 * detect / n;
    state.counters["flare_ms"] = 1e3 * flare / n;
    state.counters["write_ms"] = 1e3 * write / n;
}

void BM_SimulateCached(benchmark::State& state) {
    const ghosts::GhostTable& table = cachedTable();
    std::size_t ghostCount = 0;
    frame(state, plateWith(static_cast<int>(state.range(0))), [&](const std::vector<ghosts::Light>& lights) {
        const auto ghosts = scene::fourierGhosts(ghosts::instantiate(table, lights, {kW, kH, 36.0 / kW}));
        ghostCount = ghosts.size();
        return fourier::renderFourier(ghosts, kW, kH, {}).image;
    });
    state.counters["ghosts"] = double(ghostCount);
}
BENCHMARK(BM_SimulateCached)->Arg(3)->Arg(300)->Unit(benchmark::kMillisecond)->UseRealTime();

// Shaped frames with the polygons drawn by `raster` (null: the CPU's coverage raster).
void shapedFrames(benchmark::State& state, ghosts::PolygonRaster* raster) {
    const ghosts::ShapedTable& table = shapedTable();
    const trace::ImageFrame sensorFrame{kW, kH, 36.0 / kW};
    ghosts::ShapedRender stats;
    frame(state, plateWith(static_cast<int>(state.range(0))), [&](const std::vector<ghosts::Light>& lights) {
        return scene::renderShapedScene(lens(), table, lights, sensorFrame, trace::SensorPlane::File, &stats, nullptr,
                                        raster);
    });
    state.counters["instances"] = double(stats.drawn);
    state.counters["triangles"] = double(stats.triangles);
    // The subdivision's cost against what it draws: triangles per pixel covered (the mean over the
    // direct instances and channels, the largest), and the gridded instances' triangles.
    state.counters["tri_per_px"] = stats.trianglesPerPixel;
    state.counters["tri_per_px_max"] = stats.mostTrianglesPerPixel;
    state.counters["grid_triangles"] = double(stats.gridTriangles);
}

void BM_SimulateShaped(benchmark::State& state) {
    shapedFrames(state, nullptr);
}
BENCHMARK(BM_SimulateShaped)->Arg(3)->Arg(30)->Arg(300)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same frames with the polygons drawn by the GL backend (gpu::GlPolygonRaster; llvmpipe without
// a GPU): flare_ms against BM_SimulateShaped's is the GPU's share.
void BM_SimulateShapedGl(benchmark::State& state) {
    const gpu::GlContext* context =
        bench::glContextFor(state, state.range(0) > 3, "158 s for 300 lights on llvmpipe, 2 cores");
    if (!context) return;
    gpu::GlPolygonRaster raster(*context);
    shapedFrames(state, &raster);
}
BENCHMARK(BM_SimulateShapedGl)->Arg(3)->Arg(30)->Arg(300)->Unit(benchmark::kMillisecond)->UseRealTime();

// The polygons made and thrown away: flare_ms is what stays on the CPU when a device rasterises.
void BM_ShapedPolygonsOnly(benchmark::State& state) {
    struct Discard final : ghosts::PolygonRaster {
        std::vector<std::vector<double>> image;
        void begin(const trace::ImageFrame& f, std::size_t channels, double) override {
            image.assign(channels, std::vector<double>(static_cast<std::size_t>(f.width) * f.height, 0.0));
        }
        void draw(std::size_t, const ghosts::ShapedPolygons&) override {}
        std::vector<std::vector<double>> finish() override { return std::move(image); }
    } discard;
    shapedFrames(state, &discard);
}
BENCHMARK(BM_ShapedPolygonsOnly)->Arg(3)->Arg(30)->Arg(300)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ShapedTableBuild(benchmark::State& state) {
    ghosts::TableSettings s;
    s.sensorSizeMm = {36.0, 36.0 * kH / kW};
    for (auto _ : state) {
        const ghosts::ShapedTable t = ghosts::buildShapedTable(lens(), s);
        benchmark::DoNotOptimize(t.ghosts.data());
    }
}
BENCHMARK(BM_ShapedTableBuild)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// Decoding the cache entry (held in memory: the file's read is the disk's).
void BM_ShapedTableLoad(benchmark::State& state) {
    const std::string& bytes = shapedBytes();
    for (auto _ : state) {
        std::string key;
        const ghosts::ShapedTable t = ghosts::shapedTableFromBytes(bytes, "bench", key);
        benchmark::DoNotOptimize(t.ghosts.data());
    }
    state.counters["entry_MB"] = double(bytes.size()) / 1e6;
}
BENCHMARK(BM_ShapedTableLoad)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SimulateUncached(benchmark::State& state) {
    double build = 0.0;
    for (auto _ : state) {
        const auto t = std::chrono::steady_clock::now();
        const ghosts::GhostTable table = ghosts::buildGhostTable(lens(), ghosts::TableSettings{});
        build += std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        benchmark::DoNotOptimize(table.ghosts.data());
    }
    state.counters["table_s"] = build / double(state.iterations());
}
BENCHMARK(BM_SimulateUncached)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// Writing simulate's 9 channels (plate RGB, flare.*, composite.*) at 1920 x 1080, zip: OpenEXR
// compressing on one thread (the baseline) and on every core (what the tool does).
void BM_WriteExr9Channels(benchmark::State& state) {
    std::vector<float> px(static_cast<std::size_t>(kW) * kH * 9);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 9; ++c)
                px[(static_cast<std::size_t>(y) * kW + x) * 9 + c] =
                    static_cast<float>(c + std::sin(0.01 * (c + 1) * x) * std::cos(0.013 * y));
    const std::vector<std::string> names = {"R",       "G",           "B",           "flare.R",    "flare.G",
                                            "flare.B", "composite.R", "composite.G", "composite.B"};
    const auto out = std::filesystem::temp_directory_path() / "ff-bench-write.exr";
    int before = 0;
    OIIO::getattribute("exr_threads", before);
    OIIO::attribute("exr_threads", static_cast<int>(state.range(0)));
    for (auto _ : state) image::writeExr(out.string(), kW, kH, names, px, {});
    OIIO::attribute("exr_threads", before);
}
BENCHMARK(BM_WriteExr9Channels)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
