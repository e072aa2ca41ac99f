// The diffraction stage (docs/diffraction.md, docs/performance.md): the RGB PSF of the bundled double
// Gauss stopped down to f/8 with 6 blades (8 wavelengths, transform 2048), binned at the pixel pitch of
// a 36 mm wide sensor at 1920 and 3840 pixels across; the PSF with the lens's traced wavefront (the
// double Gauss at f/2, a light 15.5 mm from the axis: --diffraction traced's cost per tile); and the
// convolution of a frame of lights with it
// (three channels, double-precision FFTs), at 1920 x 1080 and 3840 x 2160, with FFTW on the CPU and
// with the GL backend's compute-shader FFT (llvmpipe without a GPU: 1080p only there).

#include "diffraction/convolution.h"
#include "diffraction/psf.h"
#include "diffraction/wavefront.h"
#include "gpu/gl_fft.h"
#include "optics/lens_loader.h"

#include <benchmark/benchmark.h>

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

// The layer of 300 lights at the frame's pitch, convolved by `device` (null: FFTW).
void layers(benchmark::State& state, Convolver* device) {
    const int W = kWidths[state.range(0)], H = W * 9 / 16;
    PsfSettings s;
    s.pitchMm = 36.0 / W;
    const Psf psf = pixelPsf(aperture(), s);
    std::vector<float> lights(static_cast<std::size_t>(W) * H * 3, 0.0f);
    std::mt19937 rng(1);
    for (int k = 0; k < 300; ++k) {
        const std::size_t p = (static_cast<std::size_t>(rng() % H) * W + rng() % W) * 3;
        lights[p] = lights[p + 1] = lights[p + 2] = 1000.0f;
    }
    for (auto _ : state) {
        const auto layer = diffractionLayer(lights, W, H, psf, 1.0, nullptr, device);
        benchmark::DoNotOptimize(layer.data());
    }
    state.counters["radius_px"] = psf.radius;
}

void BM_Convolve(benchmark::State& state) {
    layers(state, nullptr);
}
BENCHMARK(BM_Convolve)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ConvolveGl(benchmark::State& state) {
    const ff::gpu::GlContext* context = ff::bench::glContextFor(state, state.range(0) > 0, "2160p");
    if (!context) return;
    ff::gpu::GlFft fft(*context);
    layers(state, &fft);
}
BENCHMARK(BM_ConvolveGl)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
