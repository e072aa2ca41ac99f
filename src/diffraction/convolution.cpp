#include "diffraction/convolution.h"

#include "core/error.h"
#include "fourier/fftw_planner.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

namespace ff::diffraction {

namespace {

// The smallest size >= n whose factors are 2, 3, 5 and 7 (FFTW's fast sizes).
int fastSize(int n) {
    for (int m = std::max(n, 1);; ++m) {
        int r = m;
        for (int f : {2, 3, 5, 7})
            while (r % f == 0) r /= f;
        if (r == 1) return m;
    }
}

struct Plans {
    fftwf_plan forward = nullptr, backward = nullptr;
    ~Plans() {
        std::lock_guard<std::mutex> lock(fourier::fftwPlannerMutex());
        if (forward) fftwf_destroy_plan(forward);
        if (backward) fftwf_destroy_plan(backward);
    }
};

} // namespace

std::vector<float> convolve(const std::vector<float>& image, int width, int height, const Psf& psf, double* offFrame) {
    const std::size_t pixels = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
    if (image.size() != pixels * 3) throw Error(ErrorKind::Runtime, "convolve: the image does not match its size");
    std::vector<float> out(pixels * 3, 0.0f);
    if (pixels == 0) return out;
    const int R = psf.radius, kw = psf.width();
    // Linear convolution: the kernel reaches R beyond the frame, so a period of W + R keeps what
    // wraps around out of the frame.
    const int Wp = fastSize(width + R), Hp = fastSize(height + R);
    const std::size_t real = static_cast<std::size_t>(Wp) * Hp, complex = static_cast<std::size_t>(Hp) * (Wp / 2 + 1);
    Plans plans;
    {
        auto a = fourier::fftwArray<float>(real);
        auto b = fourier::fftwArray<fftwf_complex>(complex);
        if (!a || !b) throw Error(ErrorKind::Runtime, "out of memory for the diffraction's transforms");
        std::lock_guard<std::mutex> lock(fourier::fftwPlannerMutex());
        plans.forward = fftwf_plan_dft_r2c_2d(Hp, Wp, a.get(), b.get(), FFTW_ESTIMATE);
        plans.backward = fftwf_plan_dft_c2r_2d(Hp, Wp, b.get(), a.get(), FFTW_ESTIMATE);
    }
    if (!plans.forward || !plans.backward)
        throw Error(ErrorKind::Runtime, "FFTW could not plan the diffraction's transforms");
    std::array<double, 3> off{};
    tbb::parallel_for(0, 3, [&](int c) {
        auto img = fourier::fftwArray<float>(real);
        auto ker = fourier::fftwArray<float>(real);
        auto I = fourier::fftwArray<fftwf_complex>(complex);
        auto K = fourier::fftwArray<fftwf_complex>(complex);
        if (!img || !ker || !I || !K) throw Error(ErrorKind::Runtime, "out of memory for the diffraction's transforms");
        std::fill(img.get(), img.get() + real, 0.0f);
        std::fill(ker.get(), ker.get() + real, 0.0f);
        double in = 0.0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const float v = image[(static_cast<std::size_t>(y) * width + x) * 3 + c];
                img.get()[static_cast<std::size_t>(y) * Wp + x] = v;
                in += v;
            }
        // The kernel's centre at (0, 0), offsets wrapped around the period.
        for (int dy = -R; dy <= R; ++dy)
            for (int dx = -R; dx <= R; ++dx)
                ker.get()[static_cast<std::size_t>((dy + Hp) % Hp) * Wp + (dx + Wp) % Wp] =
                    psf.channel[c][static_cast<std::size_t>(dy + R) * kw + (dx + R)];
        fftwf_execute_dft_r2c(plans.forward, img.get(), I.get());
        fftwf_execute_dft_r2c(plans.forward, ker.get(), K.get());
        const float scale = 1.0f / static_cast<float>(real);
        for (std::size_t k = 0; k < complex; ++k) {
            const float re = I.get()[k][0] * K.get()[k][0] - I.get()[k][1] * K.get()[k][1];
            const float im = I.get()[k][0] * K.get()[k][1] + I.get()[k][1] * K.get()[k][0];
            I.get()[k][0] = re * scale;
            I.get()[k][1] = im * scale;
        }
        fftwf_execute_dft_c2r(plans.backward, I.get(), img.get());
        double kept = 0.0, kernel = 0.0;
        for (float v : psf.channel[c]) kernel += v;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const float v = img.get()[static_cast<std::size_t>(y) * Wp + x];
                out[(static_cast<std::size_t>(y) * width + x) * 3 + c] = v;
                kept += v;
            }
        off[static_cast<std::size_t>(c)] = std::max(0.0, in * kernel - kept);
    });
    if (offFrame) *offFrame += off[0] + off[1] + off[2];
    return out;
}

std::vector<float> diffractionLayer(const std::vector<float>& lights, int width, int height, const Psf& psf,
                                    double gain, double* offFrame) {
    double off = 0.0;
    std::vector<float> spread = convolve(lights, width, height, psf, &off);
    if (offFrame) *offFrame += gain * off;
    const float g = static_cast<float>(gain);
    for (std::size_t i = 0; i < spread.size(); ++i) spread[i] = std::max(g * (spread[i] - lights[i]), -lights[i]);
    return spread;
}

} // namespace ff::diffraction
