#include "gpu/gl_fft.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>

namespace ff::gpu {

std::string_view embedded(std::string_view name);

namespace {

constexpr int kGroup = 64;
constexpr GLuint kMaxGroups = 65535; // work groups per dispatch dimension every GL 4.5 device allows
constexpr int kMaxSide = 16384;

bool powerOfTwo(int n) {
    return n > 0 && (n & (n - 1)) == 0;
}
int nextPowerOfTwo(int n) {
    int p = 1;
    while (p < n) p *= 2;
    return p;
}

} // namespace

GlFft::GlFft(const GlContext&)
    : a_(std::make_unique<Buffer>()), b_(std::make_unique<Buffer>()), scratch_(std::make_unique<Buffer>()) {
    pass_ = std::make_unique<ComputeProgram>("fft_pass.comp", embedded("fft_pass.comp"), kGroup);
    product_ = std::make_unique<ComputeProgram>("spectrum_product.comp", embedded("spectrum_product.comp"), kGroup);
}

GlFft::~GlFft() = default;

void GlFft::twiddles(int length) {
    if (length <= twiddleLength_) return;
    // exp(-2 pi i q / L) for q < L / 2.
    std::vector<double> w(static_cast<std::size_t>(length));
    for (int q = 0; q < length / 2; ++q) {
        const double a = -2.0 * std::numbers::pi * q / length;
        w[static_cast<std::size_t>(2 * q)] = std::cos(a);
        w[static_cast<std::size_t>(2 * q + 1)] = std::sin(a);
    }
    twiddle_.upload(w.data(), w.size() * sizeof(double));
    twiddleLength_ = length;
}

void GlFft::transform(std::unique_ptr<Buffer>& data, std::unique_ptr<Buffer>& scratch, int width, int height,
                      bool inverse) {
    twiddles(std::max(width, height));
    scratch->upload(nullptr, static_cast<std::size_t>(width) * height * 2 * sizeof(double));
    pass_->use();
    pass_->set("inverse", inverse ? 1 : 0);
    twiddle_.bind(2);
    // Rows (stride 1, one transform per row), then columns (stride = width, one per column).
    for (const auto [n, stride, batch, count] :
         {std::array<int, 4>{width, 1, width, height}, std::array<int, 4>{height, width, 1, width}}) {
        pass_->set("n", n);
        pass_->set("stride", stride);
        pass_->set("batch", batch);
        pass_->set("count", count);
        // Along columns the invocations of a work group take neighbouring columns, so that they read
        // and write neighbouring memory; along rows, neighbouring butterflies.
        const bool across = stride != 1;
        pass_->set("across", across ? 1 : 0);
        const auto inner = static_cast<GLuint>(across ? count : n / 2),
                   outer = static_cast<GLuint>(across ? n / 2 : count);
        const GLuint groupsX = (inner + kGroup - 1) / kGroup;
        for (int ns = 1; ns < n; ns *= 2) {
            pass_->set("ns", ns);
            pass_->set("step", twiddleLength_ / (2 * ns));
            data->bind(0);
            scratch->bind(1);
            glDispatchCompute(groupsX, std::min(outer, kMaxGroups), (outer + kMaxGroups - 1) / kMaxGroups);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            std::swap(data, scratch);
        }
    }
    checkGl("fft_pass.comp");
}

std::vector<std::complex<double>> GlFft::transform(const std::vector<std::complex<double>>& data, int width, int height,
                                                   bool inverse) {
    if (!powerOfTwo(width) || !powerOfTwo(height) || width > kMaxSide || height > kMaxSide ||
        data.size() != static_cast<std::size_t>(width) * height)
        throw Error(ErrorKind::Runtime, "GlFft: the array must be a power of 2 per side, up to 16384");
    a_->upload(data.data(), data.size() * sizeof(std::complex<double>));
    transform(a_, scratch_, width, height, inverse);
    std::vector<std::complex<double>> out(data.size());
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    a_->download(out.data(), out.size() * sizeof(std::complex<double>));
    return out;
}

std::vector<float> GlFft::convolve(const std::vector<float>& image, int width, int height, const diffraction::Psf& psf,
                                   double* offFrame) {
    const std::size_t pixels = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
    if (image.size() != pixels * 3) throw Error(ErrorKind::Runtime, "convolve: the image does not match its size");
    std::vector<float> out(pixels * 3, 0.0f);
    if (pixels == 0) return out;
    const auto [rx, ry] = diffraction::kernelReach(image, width, height, psf);
    // Linear convolution: a period of at least W + rx keeps what wraps around out of the frame.
    const int P = nextPowerOfTwo(width + rx), Q = nextPowerOfTwo(height + ry);
    if (P > kMaxSide || Q > kMaxSide) throw Error(ErrorKind::Runtime, "the frame is too large for the GL FFT");
    const std::size_t N = static_cast<std::size_t>(P) * Q;
    std::vector<std::complex<double>> field(N), kernel(N);
    double off = 0.0;
    for (int c = 0; c < 3; ++c) {
        std::fill(field.begin(), field.end(), 0.0);
        std::fill(kernel.begin(), kernel.end(), 0.0);
        double in = 0.0, sum = 0.0, kept = 0.0;
        const std::vector<float> k = diffraction::frameKernel(psf, c, rx, ry, &sum);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const float v = image[(static_cast<std::size_t>(y) * width + x) * 3 + c];
                field[static_cast<std::size_t>(y) * P + x] = v;
                in += v;
            }
        for (int dy = -ry; dy <= ry; ++dy)
            for (int dx = -rx; dx <= rx; ++dx)
                kernel[static_cast<std::size_t>((dy + Q) % Q) * P + (dx + P) % P] =
                    k[static_cast<std::size_t>(dy + ry) * (2 * rx + 1) + (dx + rx)];
        a_->upload(field.data(), N * sizeof(std::complex<double>));
        b_->upload(kernel.data(), N * sizeof(std::complex<double>));
        transform(a_, scratch_, P, Q, false);
        transform(b_, scratch_, P, Q, false);
        product_->use();
        product_->set("count", static_cast<int>(N));
        product_->setDouble("scale", 1.0 / static_cast<double>(N));
        a_->bind(0);
        b_->bind(1);
        const auto groups = static_cast<GLuint>((N + kGroup - 1) / kGroup);
        glDispatchCompute(std::min(groups, kMaxGroups), (groups + kMaxGroups - 1) / kMaxGroups, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        checkGl("spectrum_product.comp");
        transform(a_, scratch_, P, Q, true);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        a_->download(field.data(), N * sizeof(std::complex<double>));
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const double v = field[static_cast<std::size_t>(y) * P + x].real();
                out[(static_cast<std::size_t>(y) * width + x) * 3 + c] = static_cast<float>(v);
                kept += v;
            }
        off += std::max(0.0, in * sum - kept);
    }
    if (offFrame) *offFrame += off;
    return out;
}

} // namespace ff::gpu
