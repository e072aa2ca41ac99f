// The diffraction stage (docs/diffraction.md, docs/performance.md): the RGB PSF of the bundled double
// Gauss stopped down to f/8 with 6 blades (8 wavelengths, transform 2048), binned at the pixel pitch of
// a 36 mm wide sensor at 1920 and 3840 pixels across; the PSF with the lens's traced wavefront (the
// double Gauss at f/2, a light 15.5 mm from the axis: --diffraction traced's cost per tile); the PSF
// read from the cache; and the convolution of a frame of lights with it (300 lights: by FFT; 3: the
// kernel added at each)
// (three channels, double-precision FFTs), at 1920 x 1080 and 3840 x 2160, with FFTW on the CPU and
// with the GL backend's compute-shader FFT (llvmpipe without a GPU: 1080p only there).

#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "diffraction/psf_cache.h"
#include "diffraction/wavefront.h"
#include "gpu/gl_fft.h"
#include "optics/lens_loader.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>

#include "gl_bench.h"

namespace {

using namespace ff::diffraction;

constexpr int kWidths[] = {1920, 3840};

Aperture aperture() {
    return {6, 0.0, 8.0};
}

void BM_Psf(benchmark::State& state) {
    PsfSettings s;
    s.pitchMm = 36.0 / kWidths[state.range(0)];
    int radius = 0;
    for (auto _ : state) {
        const Psf psf = pixelPsf(aperture(), s);
        radius = psf.radius;
        benchmark::DoNotOptimize(psf.channel[0].data());
    }
    state.counters["radius_px"] = radius;
}
BENCHMARK(BM_Psf)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TracedPsf(benchmark::State& state) {
    const ff::optics::Lens lens =
        ff::optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/double-gauss-50mm-f2.lens");
    PsfSettings s;
    s.pitchMm = 36.0 / kWidths[state.range(0)];
    int radius = 0;
    for (auto _ : state) {
        s.pupil = tracedPupil(lens, 13.3, 7.9);
        const Psf psf = pixelPsf(apertureOf(lens), s);
        radius = psf.radius;
        benchmark::DoNotOptimize(psf.channel[0].data());
    }
    state.counters["radius_px"] = radius;
}
BENCHMARK(BM_TracedPsf)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The aberration-free PSF read back from the cache (a warm run's cost), the cache in a folder of its own.
void BM_PsfFromCache(benchmark::State& state) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "fourierflare-bench-psf";
    setenv("FF_CACHE_DIR", dir.c_str(), 1);
    PsfSettings s;
    s.pitchMm = 36.0 / kWidths[state.range(0)];
    ff::NullReporter quiet;
    cachedPixelPsf(aperture(), s, true, quiet);
    bool hit = false;
    for (auto _ : state) {
        const Psf psf = cachedPixelPsf(aperture(), s, true, quiet, &hit);
        benchmark::DoNotOptimize(psf.channel[0].data());
    }
    if (!hit) state.SkipWithError("the PSF was not read from the cache");
    std::filesystem::remove_all(dir);
    unsetenv("FF_CACHE_DIR");
}
BENCHMARK(BM_PsfFromCache)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The layer of `lights` lights (300: the FFT; 3: the kernel added at each) at the frame's pitch,
// convolved by `device` (null: diffraction::convolve, a shot's first frame on the CPU), or by one
// made anew for each frame by `fresh` (a shot's first frame on it). A kept device has convolved one
// frame before the timing (a shot's later frames: the kernel's spectra kept).
void layers(benchmark::State& state, Convolver* device, int count = 300,
            const std::function<std::unique_ptr<Convolver>()>& fresh = nullptr) {
    const int W = kWidths[state.range(0)], H = W * 9 / 16;
    PsfSettings s;
    s.pitchMm = 36.0 / W;
    const Psf psf = pixelPsf(aperture(), s);
    std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
    std::mt19937 rng(1);
    for (int k = 0; k < count; ++k) {
        const std::size_t p = (static_cast<std::size_t>(rng() % H) * W + rng() % W) * 3;
        lights[p] = lights[p + 1] = lights[p + 2] = 1000.0f;
    }
    if (device) diffractionLayer(lights, W, H, psf, 1.0, nullptr, device);
    for (auto _ : state) {
        std::unique_ptr<Convolver> made = fresh ? fresh() : nullptr;
        const auto layer = diffractionLayer(lights, W, H, psf, 1.0, nullptr, made ? made.get() : device);
        benchmark::DoNotOptimize(layer.data());
    }
    state.counters["radius_px"] = psf.radius;
}

void BM_Convolve(benchmark::State& state) {
    FftwConvolver cpu;
    layers(state, &cpu);
}
BENCHMARK(BM_Convolve)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ConvolveFirstFrame(benchmark::State& state) {
    layers(state, nullptr);
}
BENCHMARK(BM_ConvolveFirstFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ConvolveThreeLights(benchmark::State& state) {
    layers(state, nullptr, 3);
}
BENCHMARK(BM_ConvolveThreeLights)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ConvolveGl(benchmark::State& state) {
    const ff::gpu::GlContext* context = ff::bench::glContextFor(state, state.range(0) > 0, "2160p");
    if (!context) return;
    ff::gpu::GlFft fft(*context);
    layers(state, &fft);
}
BENCHMARK(BM_ConvolveGl)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ConvolveGlFirstFrame(benchmark::State& state) {
    const ff::gpu::GlContext* context = ff::bench::glContextFor(state, state.range(0) > 0, "2160p");
    if (!context) return;
    layers(state, nullptr, 300, [&] { return std::make_unique<ff::gpu::GlFft>(*context); });
}
BENCHMARK(BM_ConvolveGlFirstFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
