#include "diffraction/convolution.h"

#include "core/error.h"
#include "diffraction/fftw.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::diffraction {

// Few lit pixels: the kernel added at each (lit x kernel area multiply-adds) costs less than the three
// transforms of the period (about 5 Wp Hp log2(Wp Hp) flops each, counted as 4 per multiply-add).
bool convolvesDirectly(std::size_t lit, int width, int height, const Psf& psf) {
    const double area = double(fastSize(width + psf.radius)) * fastSize(height + psf.radius);
    return double(lit) * psf.width() * psf.width() <= 4.0 * area * std::log2(area);
}

namespace {

// The same convolution by adding the kernel at each lit pixel: no transform's rounding, zero beyond
// the kernel's reach. Summed in double over the lit pixels' box grown by the kernel's reach, then
// rounded once to float, as the transforms' result is.
void convolveDirect(const std::vector<float>& image, int width, int height, const Psf& psf, std::vector<float>& out,
                    std::array<double, 3>& off) {
    const int R = psf.radius, kw = psf.width();
    tbb::parallel_for(0, 3, [&](int c) {
        const std::vector<float>& kernel = psf.channel[static_cast<std::size_t>(c)];
        int bx0 = width, by0 = height, bx1 = -1, by1 = -1;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                if (image[(static_cast<std::size_t>(y) * width + x) * 3 + c] != 0.0f)
                    bx0 = std::min(bx0, x), bx1 = std::max(bx1, x), by0 = std::min(by0, y), by1 = std::max(by1, y);
        if (bx1 < 0) return;
        bx0 = std::max(0, bx0 - R), by0 = std::max(0, by0 - R);
        bx1 = std::min(width - 1, bx1 + R), by1 = std::min(height - 1, by1 + R);
        const int bw = bx1 - bx0 + 1;
        std::vector<double> acc(static_cast<std::size_t>(bw) * (by1 - by0 + 1), 0.0);
        double in = 0.0, kept = 0.0, whole = 0.0;
        for (float v : kernel) whole += v;
        for (int y = by0; y <= by1; ++y)
            for (int x = bx0; x <= bx1; ++x) {
                const double v = image[(static_cast<std::size_t>(y) * width + x) * 3 + c];
                if (v == 0.0) continue;
                in += v;
                const int y0 = std::max(-R, -y), y1 = std::min(R, height - 1 - y);
                const int x0 = std::max(-R, -x), x1 = std::min(R, width - 1 - x);
                for (int dy = y0; dy <= y1; ++dy) {
                    const float* k = &kernel[static_cast<std::size_t>(dy + R) * kw + (x0 + R)];
                    double* a = &acc[static_cast<std::size_t>(y + dy - by0) * bw + (x + x0 - bx0)];
                    for (int dx = 0; dx <= x1 - x0; ++dx) a[dx] += v * k[dx];
                }
            }
        for (int y = by0; y <= by1; ++y)
            for (int x = bx0; x <= bx1; ++x) {
                const double v = acc[static_cast<std::size_t>(y - by0) * bw + (x - bx0)];
                out[(static_cast<std::size_t>(y) * width + x) * 3 + c] = static_cast<float>(v);
                kept += v;
            }
        off[static_cast<std::size_t>(c)] = std::max(0.0, in * whole - kept);
    });
}

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
    std::array<double, 3> off{};
    const std::size_t lit =
        static_cast<std::size_t>(std::count_if(image.begin(), image.end(), [](float v) { return v != 0.0f; }));
    if (convolvesDirectly(lit, width, height, psf)) {
        convolveDirect(image, width, height, psf, out, off);
        if (offFrame) *offFrame += off[0] + off[1] + off[2];
        return out;
    }
    const std::size_t real = static_cast<std::size_t>(Wp) * Hp, complex = static_cast<std::size_t>(Hp) * (Wp / 2 + 1);
    // In double: the transforms' rounding spreads ~1e-16 of the lights' flux over the whole frame
    // (float's 1e-7 of a 60 000-valued source is visible on a night plate).
    auto a = fftwArray<double>(real);
    auto b = fftwArray<fftw_complex>(complex);
    const Plan forward([&] { return fftw_plan_dft_r2c_2d(Hp, Wp, a.get(), b.get(), FFTW_ESTIMATE); });
    const Plan backward([&] { return fftw_plan_dft_c2r_2d(Hp, Wp, b.get(), a.get(), FFTW_ESTIMATE); });
    tbb::parallel_for(0, 3, [&](int c) {
        auto img = fftwArray<double>(real);
        auto ker = fftwArray<double>(real);
        auto I = fftwArray<fftw_complex>(complex);
        auto K = fftwArray<fftw_complex>(complex);
        std::fill(img.get(), img.get() + real, 0.0);
        std::fill(ker.get(), ker.get() + real, 0.0);
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
        fftw_execute_dft_r2c(forward.plan, img.get(), I.get());
        fftw_execute_dft_r2c(forward.plan, ker.get(), K.get());
        const double scale = 1.0 / static_cast<double>(real);
        for (std::size_t k = 0; k < complex; ++k) {
            const double re = I.get()[k][0] * K.get()[k][0] - I.get()[k][1] * K.get()[k][1];
            const double im = I.get()[k][0] * K.get()[k][1] + I.get()[k][1] * K.get()[k][0];
            I.get()[k][0] = re * scale;
            I.get()[k][1] = im * scale;
        }
        fftw_execute_dft_c2r(backward.plan, I.get(), img.get());
        double kept = 0.0, kernel = 0.0;
        for (float v : psf.channel[c]) kernel += v;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const double v = img.get()[static_cast<std::size_t>(y) * Wp + x];
                out[(static_cast<std::size_t>(y) * width + x) * 3 + c] = static_cast<float>(v);
                kept += v;
            }
        off[static_cast<std::size_t>(c)] = std::max(0.0, in * kernel - kept);
    });
    if (offFrame) *offFrame += off[0] + off[1] + off[2];
    return out;
}

std::vector<float> diffractionLayer(const std::vector<float>& lights, int width, int height, const Psf& psf,
                                    double gain, double* offFrame, Convolver* device) {
    double off = 0.0;
    std::vector<float> spread =
        device ? device->convolve(lights, width, height, psf, &off) : convolve(lights, width, height, psf, &off);
    if (offFrame) *offFrame += gain * off;
    const float g = static_cast<float>(gain);
    for (std::size_t i = 0; i < spread.size(); ++i) spread[i] = std::max(g * (spread[i] - lights[i]), -lights[i]);
    return spread;
}

std::vector<float> zonedDiffractionLayer(const std::vector<float>& lights, int width, int height, int tilesX,
                                         int tilesY, const std::function<Psf(double x, double y)>& psfAt, double gain,
                                         double* offFrame, Convolver* device) {
    std::vector<float> layer(lights.size(), 0.0f), tile(lights.size());
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            const int x0 = tx * width / tilesX, x1 = (tx + 1) * width / tilesX;
            const int y0 = ty * height / tilesY, y1 = (ty + 1) * height / tilesY;
            std::fill(tile.begin(), tile.end(), 0.0f);
            double flux = 0.0, cx = 0.0, cy = 0.0;
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const std::size_t p = (static_cast<std::size_t>(y) * width + x) * 3;
                    double sum = 0.0;
                    for (int c = 0; c < 3; ++c) sum += tile[p + c] = lights[p + c];
                    flux += sum;
                    cx += sum * (x + 0.5);
                    cy += sum * (y + 0.5);
                }
            if (!(flux > 0.0)) continue;
            const std::vector<float> part =
                diffractionLayer(tile, width, height, psfAt(cx / flux, cy / flux), gain, offFrame, device);
            for (std::size_t i = 0; i < layer.size(); ++i) layer[i] += part[i];
        }
    return layer;
}

} // namespace ff::diffraction
