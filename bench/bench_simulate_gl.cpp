// `simulate` end to end on the GL backend beside the CPU, in the same run, in a binary small enough to
// carry onto a GPU machine: no OpenImageIO (the plate is read, and the composite written, through
// OpenEXR alone, as RGBA half). The main job's stages at 1920 x 1080 with 3 and 300 point lights on
// the double Gauss (the plates bench_simulate makes): read the EXR, find the lights, the shaped flare
// (polygons drawn by gpu::GlPolygonRaster), the diffraction layer (gpu::GlFft), composite, write the
// EXR. Warm: one untimed frame first makes the tables, the PSF and the kernel's spectra, as a shot's
// first frame does. The counters are the stages' milliseconds (Simulation's own timers for the
// detection, flare and diffraction). On a software rasteriser the GL cases are skipped.

#include "gpu/backend_choice.h"
#include "image/composite.h"
#include "image/plate.h"
#include "optics/lens_loader.h"
#include "scene/simulation.h"

#include <OpenEXR/ImfRgbaFile.h>
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench_plates.h"

namespace {

using namespace ff;
constexpr int kW = bench::kPlateWidth, kH = bench::kPlateHeight;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) {
    return 1e3 * std::chrono::duration<double>(Clock::now() - t).count();
}

// bench::platePixels as an RGBA half EXR.
std::string plateWith(int lights) {
    const auto path = std::filesystem::temp_directory_path() / ("ff-bench-gl-plate-" + std::to_string(lights) + ".exr");
    if (std::filesystem::exists(path)) return path.string();
    const std::vector<float> rgb = bench::platePixels(lights);
    std::vector<Imf::Rgba> px(static_cast<std::size_t>(kW) * kH);
    for (std::size_t p = 0; p < px.size(); ++p) px[p] = Imf::Rgba(rgb[p * 3], rgb[p * 3 + 1], rgb[p * 3 + 2], 1.0f);
    Imf::RgbaOutputFile out(path.c_str(), kW, kH, Imf::WRITE_RGBA);
    out.setFrameBuffer(px.data(), 1, kW);
    out.writePixels(kH);
    return path.string();
}

image::Plate readPlate(const std::string& path) {
    Imf::RgbaInputFile in(path.c_str());
    const Imath::Box2i dw = in.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    std::vector<Imf::Rgba> px(static_cast<std::size_t>(w) * h);
    in.setFrameBuffer(px.data() - dw.min.x - static_cast<std::ptrdiff_t>(dw.min.y) * w, 1, static_cast<std::size_t>(w));
    in.readPixels(dw.min.y, dw.max.y);
    std::vector<float> rgb(px.size() * 3);
    for (std::size_t p = 0; p < px.size(); ++p) {
        rgb[p * 3] = px[p].r;
        rgb[p * 3 + 1] = px[p].g;
        rgb[p * 3 + 2] = px[p].b;
    }
    return image::plateFromPixels(path, w, h, {"R", "G", "B"}, std::move(rgb));
}

void writeComposite(const std::string& path, int w, int h, const std::vector<float>& rgb) {
    std::vector<Imf::Rgba> px(static_cast<std::size_t>(w) * h);
    for (std::size_t p = 0; p < px.size(); ++p) px[p] = Imf::Rgba(rgb[p * 3], rgb[p * 3 + 1], rgb[p * 3 + 2], 1.0f);
    Imf::RgbaOutputFile out(path.c_str(), w, h, Imf::WRITE_RGBA);
    out.setFrameBuffer(px.data(), 1, static_cast<std::size_t>(w));
    out.writePixels(h);
}

// The bundled lens: from the source tree this was built in, else from the working directory (a copy
// of the repository on another machine).
std::string lensPath() {
    const std::filesystem::path built = std::filesystem::path(FF_SOURCE_DIR) / "lenses/double-gauss-50mm-f2.lens";
    return std::filesystem::exists(built) ? built.string() : "lenses/double-gauss-50mm-f2.lens";
}

// range(0): 0 the CPU, 1 the GL backend; range(1): lights.
void BM_Simulate(benchmark::State& state) {
    const bool gl = state.range(0) == 1;
    const int lights = static_cast<int>(state.range(1));
    scene::SimulationSettings s;
    std::shared_ptr<gpu::GlBackend> backend;
    if (gl) {
        std::string why;
        backend = gpu::openBackend("auto", why);
        if (!backend) {
            state.SkipWithError(("no GPU: " + why).c_str());
            return;
        }
        state.SetLabel(backend->context().renderer());
        s.fourier.backend = backend;
        s.raster = gpu::polygonRaster(s.fourier);
        s.convolver = gpu::diffractionDevice(s.fourier);
    }
    NullReporter quiet;
    scene::Simulation sim(optics::loadLens(lensPath()), s, quiet);
    const std::string in = plateWith(lights);
    const std::string out = (std::filesystem::temp_directory_path() / "ff-bench-gl-out.exr").string();
    sim.run(readPlate(in)); // the tables, the PSF and the kernel's spectra
    double read = 0.0, detect = 0.0, flare = 0.0, diffraction = 0.0, write = 0.0, total = 0.0;
    for (auto _ : state) {
        const auto start = Clock::now();
        auto t = Clock::now();
        const image::Plate plate = readPlate(in);
        read += msSince(t);
        const scene::SimulatedPlate r = sim.run(plate);
        detect += 1e3 * r.detectSeconds;
        flare += 1e3 * r.flareSeconds;
        diffraction += 1e3 * r.diffractionSeconds;
        t = Clock::now();
        writeComposite(out, plate.width, plate.height, r.composite);
        write += msSince(t);
        total += msSince(start);
    }
    const double n = static_cast<double>(state.iterations());
    state.counters["read_ms"] = read / n;
    state.counters["detect_ms"] = detect / n;
    state.counters["flare_ms"] = flare / n;
    state.counters["diffraction_ms"] = diffraction / n;
    state.counters["write_ms"] = write / n;
    state.counters["total_ms"] = total / n;
}
BENCHMARK(BM_Simulate)
    ->ArgsProduct({{0, 1}, {3, 300}})
    ->ArgNames({"gl", "lights"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace

BENCHMARK_MAIN();
