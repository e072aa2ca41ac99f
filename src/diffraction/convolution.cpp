#include "diffraction/convolution.h"

#include "core/error.h"
#include "diffraction/fftw.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace ff::diffraction {

namespace {} // namespace

std::vector<float> frameKernel(const Psf& psf, int c, int rx, int ry, double* total) {
    if (rx < 0 || ry < 0) throw Error(ErrorKind::Runtime, "frameKernel: a negative reach");
    const int kw = 2 * rx + 1, R = psf.radius, pw = psf.width();
    std::vector<float> k(static_cast<std::size_t>(kw) * (2 * ry + 1), 0.0f);
    double sum = 0.0;
    for (int y = -std::min(R, ry); y <= std::min(R, ry); ++y)
        for (int x = -std::min(R, rx); x <= std::min(R, rx); ++x)
            k[static_cast<std::size_t>(y + ry) * kw + (x + rx)] =
                psf.channel[static_cast<std::size_t>(c)][static_cast<std::size_t>(y + R) * pw + (x + R)];
    for (float v : psf.channel[static_cast<std::size_t>(c)]) sum += v;
    if (!psf.far.empty()) {
        psf.far.forEach(c, rx, ry, R, [&](int x, int y, double v) {
            k[static_cast<std::size_t>(y + ry) * kw + (x + rx)] += static_cast<float>(v);
        });
        sum = 1.0;
    }
    if (total) *total = sum;
    return k;
}

std::array<int, 2> kernelReach(const std::vector<float>& image, int width, int height, const Psf& psf) {
    if (psf.far.empty()) return {psf.radius, psf.radius};
    int x0 = width, y0 = height, x1 = -1, y1 = -1;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float* p = &image[(static_cast<std::size_t>(y) * width + x) * 3];
            if (p[0] != 0.0f || p[1] != 0.0f || p[2] != 0.0f)
                x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
    if (x1 < 0) return {0, 0};
    return {std::max(x1, width - 1 - x0), std::max(y1, height - 1 - y0)};
}

namespace {

// Few lit pixels: the kernel added at each (lit x the frame's share of the kernel multiply-adds)
// costs less than the three transforms of the period (about 5 Wp Hp log2(Wp Hp) flops each, counted
// as 4 per multiply-add).
bool direct(std::size_t lit, int width, int height, int rx, int ry) {
    const double area = double(fastSize(width + rx)) * fastSize(height + ry);
    const double added = double(std::min(2 * rx + 1, width)) * std::min(2 * ry + 1, height);
    return double(lit) * added <= 4.0 * area * std::log2(area);
}

// The same convolution by adding the kernel at each lit pixel: no transform's rounding, zero beyond
// the kernel's reach. Summed in double over the lit pixels' box grown by the kernel's reach, then
// rounded once to float, as the transforms' result is.
void convolveDirect(const std::vector<float>& image, int width, int height, const Psf& psf, int rx, int ry,
                    std::vector<float>& out, std::array<double, 3>& off) {
    const int kw = 2 * rx + 1;
    tbb::parallel_for(0, 3, [&](int c) {
        int bx0 = width, by0 = height, bx1 = -1, by1 = -1;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                if (image[(static_cast<std::size_t>(y) * width + x) * 3 + c] != 0.0f)
                    bx0 = std::min(bx0, x), bx1 = std::max(bx1, x), by0 = std::min(by0, y), by1 = std::max(by1, y);
        if (bx1 < 0) return;
        double whole = 0.0;
        const std::vector<float> kernel = frameKernel(psf, c, rx, ry, &whole);
        bx0 = std::max(0, bx0 - rx), by0 = std::max(0, by0 - ry);
        bx1 = std::min(width - 1, bx1 + rx), by1 = std::min(height - 1, by1 + ry);
        const int bw = bx1 - bx0 + 1;
        std::vector<double> acc(static_cast<std::size_t>(bw) * (by1 - by0 + 1), 0.0);
        double in = 0.0, kept = 0.0;
        for (int y = by0; y <= by1; ++y)
            for (int x = bx0; x <= bx1; ++x) {
                const double v = image[(static_cast<std::size_t>(y) * width + x) * 3 + c];
                if (v == 0.0) continue;
                in += v;
                const int y0 = std::max(-ry, -y), y1 = std::min(ry, height - 1 - y);
                const int x0 = std::max(-rx, -x), x1 = std::min(rx, width - 1 - x);
                for (int dy = y0; dy <= y1; ++dy) {
                    const float* k = &kernel[static_cast<std::size_t>(dy + ry) * kw + (x0 + rx)];
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

bool convolvesDirectly(const std::vector<float>& image, int width, int height, const Psf& psf) {
    const std::size_t lit =
        static_cast<std::size_t>(std::count_if(image.begin(), image.end(), [](float v) { return v != 0.0f; }));
    const auto [rx, ry] = kernelReach(image, width, height, psf);
    return direct(lit, width, height, rx, ry);
}

std::vector<float> convolve(const std::vector<float>& image, int width, int height, const Psf& psf, double* offFrame) {
    const std::size_t pixels = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
    if (image.size() != pixels * 3) throw Error(ErrorKind::Runtime, "convolve: the image does not match its size");
    std::vector<float> out(pixels * 3, 0.0f);
    if (pixels == 0) return out;
    const auto [rx, ry] = kernelReach(image, width, height, psf);
    // Linear convolution: the kernel reaches rx beyond the frame, so a period of W + rx keeps what
    // wraps around out of the frame.
    const int Wp = fastSize(width + rx), Hp = fastSize(height + ry);
    std::array<double, 3> off{};
    const std::size_t lit =
        static_cast<std::size_t>(std::count_if(image.begin(), image.end(), [](float v) { return v != 0.0f; }));
    if (direct(lit, width, height, rx, ry)) {
        convolveDirect(image, width, height, psf, rx, ry, out, off);
        if (offFrame) *offFrame += off[0] + off[1] + off[2];
        return out;
    }
    // In place: each row padded to Wp / 2 + 1 complex values. In double: the transforms' rounding
    // spreads ~1e-16 of the lights' flux over the whole frame (float's 1e-7 of a 60 000-valued
    // source is visible on a night plate).
    const std::size_t row = 2 * (static_cast<std::size_t>(Wp) / 2 + 1), size = row * Hp;
    const std::size_t complex = size / 2;
    auto a = fftwArray<double>(size);
    const Plan forward(
        [&] { return fftw_plan_dft_r2c_2d(Hp, Wp, a.get(), reinterpret_cast<fftw_complex*>(a.get()), FFTW_ESTIMATE); });
    const Plan backward(
        [&] { return fftw_plan_dft_c2r_2d(Hp, Wp, reinterpret_cast<fftw_complex*>(a.get()), a.get(), FFTW_ESTIMATE); });
    tbb::parallel_for(0, 3, [&](int c) {
        auto img = fftwArray<double>(size);
        auto ker = fftwArray<double>(size);
        std::fill(img.get(), img.get() + size, 0.0);
        std::fill(ker.get(), ker.get() + size, 0.0);
        double in = 0.0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const float v = image[(static_cast<std::size_t>(y) * width + x) * 3 + c];
                img.get()[static_cast<std::size_t>(y) * row + x] = v;
                in += v;
            }
        // The kernel's centre at (0, 0), offsets wrapped around the period.
        double whole = 0.0;
        {
            const std::vector<float> kernel = frameKernel(psf, c, rx, ry, &whole);
            const std::size_t kw = static_cast<std::size_t>(2 * rx + 1);
            for (int dy = -ry; dy <= ry; ++dy)
                for (int dx = -rx; dx <= rx; ++dx)
                    ker.get()[static_cast<std::size_t>((dy + Hp) % Hp) * row + (dx + Wp) % Wp] =
                        kernel[static_cast<std::size_t>(dy + ry) * kw + (dx + rx)];
        }
        auto* I = reinterpret_cast<fftw_complex*>(img.get());
        auto* K = reinterpret_cast<fftw_complex*>(ker.get());
        fftw_execute_dft_r2c(forward.plan, img.get(), I);
        fftw_execute_dft_r2c(forward.plan, ker.get(), K);
        const double scale = 1.0 / (static_cast<double>(Wp) * Hp);
        for (std::size_t k = 0; k < complex; ++k) {
            const double re = I[k][0] * K[k][0] - I[k][1] * K[k][1];
            const double im = I[k][0] * K[k][1] + I[k][1] * K[k][0];
            I[k][0] = re * scale;
            I[k][1] = im * scale;
        }
        fftw_execute_dft_c2r(backward.plan, I, img.get());
        double kept = 0.0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const double v = img.get()[static_cast<std::size_t>(y) * row + x];
                out[(static_cast<std::size_t>(y) * width + x) * 3 + c] = static_cast<float>(v);
                kept += v;
            }
        off[static_cast<std::size_t>(c)] = std::max(0.0, in * whole - kept);
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
