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
constexpr int kMaxSide = 16384;

// The radices of a length's passes, 4 while it divides, then 2, then 3 (empty: not 2^a 3^b).
std::vector<int> radices(int n) {
    std::vector<int> out;
    if (n < 1) return out;
    while (n % 4 == 0) out.push_back(4), n /= 4;
    if (n % 2 == 0) out.push_back(2), n /= 2;
    while (n % 3 == 0) out.push_back(3), n /= 3;
    if (n != 1) out.clear();
    return out;
}
bool smooth(int n) {
    return n == 1 || !radices(n).empty();
}
// The smallest 2^a 3^b >= n.
int nextSmooth(int n) {
    int best = 1;
    while (best < n) best *= 2;
    for (int three = 3; three < best; three *= 3)
        for (int p = three; p < best; p *= 2)
            if (p >= n) best = p;
    return best;
}

} // namespace

GlFft::GlFft(const GlContext&) : a_(std::make_unique<Buffer>()), scratch_(std::make_unique<Buffer>()) {
    pass_ = std::make_unique<ComputeProgram>("fft_pass.comp", embedded("fft_pass.comp"), kGroup);
    product_ = std::make_unique<ComputeProgram>("spectrum_product.comp", embedded("spectrum_product.comp"), kGroup);
    scatter_ = std::make_unique<ComputeProgram>("fft_scatter.comp", embedded("fft_scatter.comp"), kGroup);
    gather_ = std::make_unique<ComputeProgram>("fft_gather.comp", embedded("fft_gather.comp"), kGroup);
}

GlFft::~GlFft() = default;

const Buffer& GlFft::twiddles(int length) {
    auto& table = twiddles_[length];
    if (table) return *table;
    // exp(-2 pi i q / n) for q < n.
    std::vector<double> w(2 * static_cast<std::size_t>(length));
    for (int q = 0; q < length; ++q) {
        const double a = -2.0 * std::numbers::pi * q / length;
        w[static_cast<std::size_t>(2 * q)] = std::cos(a);
        w[static_cast<std::size_t>(2 * q + 1)] = std::sin(a);
    }
    table = std::make_unique<Buffer>();
    table->upload(w.data(), w.size() * sizeof(double));
    return *table;
}

void GlFft::transform(std::unique_ptr<Buffer>& data, std::unique_ptr<Buffer>& scratch, int width, int height,
                      bool inverse, int used) {
    if (used <= 0 || used > height) used = height;
    const std::size_t rowBytes = static_cast<std::size_t>(width) * 2 * sizeof(double);
    scratch->upload(nullptr, rowBytes * height);
    // The forward transform's rows from `used` on are zero, and stay so through the row passes,
    // which skip them: both buffers hold zeros there.
    if (!inverse && used < height) {
        data->zeros(rowBytes * used, rowBytes * (height - used));
        scratch->zeros(rowBytes * used, rowBytes * (height - used));
    }
    pass_->use();
    pass_->set("inverse", inverse ? 1 : 0);
    // Length n, element stride, transform stride, transforms: along rows (stride 1, one transform
    // per row) or columns (stride = width, one per column).
    const auto passes = [&](int n, int stride, int batch, int count) {
        pass_->set("n", n);
        pass_->set("stride", stride);
        pass_->set("batch", batch);
        pass_->set("count", count);
        // Along columns the invocations of a work group take neighbouring columns, so that they read
        // and write neighbouring memory; along rows, neighbouring butterflies.
        const bool across = stride != 1;
        pass_->set("across", across ? 1 : 0);
        twiddles(n).bind(2);
        int ns = 1;
        for (const int radix : radices(n)) {
            const auto inner = static_cast<GLuint>(across ? count : n / radix),
                       outer = static_cast<GLuint>(across ? n / radix : count);
            const GLuint groupsX = (inner + kGroup - 1) / kGroup;
            pass_->set("radix", radix);
            pass_->set("ns", ns);
            data->bind(0);
            scratch->bind(1);
            glDispatchCompute(groupsX, std::min(outer, kMaxWorkGroups), (outer + kMaxWorkGroups - 1) / kMaxWorkGroups);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            std::swap(data, scratch);
            ns *= radix;
        }
    };
    // Forward: the `used` rows, then every column; inverse: every column, then the `used` rows.
    if (!inverse) passes(width, 1, width, used);
    passes(height, width, 1, width);
    if (inverse) passes(width, 1, width, used);
    checkGl("fft_pass.comp");
}

std::vector<std::complex<double>> GlFft::transform(const std::vector<std::complex<double>>& data, int width, int height,
                                                   bool inverse) {
    if (!smooth(width) || !smooth(height) || width > kMaxSide || height > kMaxSide ||
        data.size() != static_cast<std::size_t>(width) * height)
        throw Error(ErrorKind::Runtime, "GlFft: the array's sides must be products of 2s and 3s, up to 16384");
    a_->upload(data.data(), data.size() * sizeof(std::complex<double>));
    transform(a_, scratch_, width, height, inverse);
    std::vector<std::complex<double>> out(data.size());
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    a_->download(out.data(), out.size() * sizeof(std::complex<double>));
    return out;
}

void GlFft::dispatch(std::size_t invocations) const {
    const auto groups = static_cast<GLuint>((invocations + kGroup - 1) / kGroup);
    dispatchGroups(groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void GlFft::kernelSpectra(const diffraction::Psf& psf, int width, int height, int period, int rows) {
    const KernelKey key{diffraction::kernelFingerprint(psf), width, height, period, rows};
    if (key == key_ && spectrum_[0]) return;
    // Every offset that cannot wrap around the period into the frame (at least the lights' reach,
    // kernelReach): the same spectrum then serves any lights in a frame of this size.
    const int kx = std::min(width - 1, period - width), ky = std::min(height - 1, rows - height);
    const std::size_t N = static_cast<std::size_t>(period) * rows;
    std::vector<std::complex<double>> kernel(N);
    for (int c = 0; c < 3; ++c) {
        std::fill(kernel.begin(), kernel.end(), 0.0);
        const std::vector<float> k = diffraction::frameKernel(psf, c, kx, ky, &flux_[static_cast<std::size_t>(c)]);
        for (int dy = -ky; dy <= ky; ++dy)
            for (int dx = -kx; dx <= kx; ++dx)
                kernel[static_cast<std::size_t>((dy + rows) % rows) * period + (dx + period) % period] =
                    k[static_cast<std::size_t>(dy + ky) * (2 * kx + 1) + (dx + kx)];
        auto& s = spectrum_[static_cast<std::size_t>(c)];
        if (!s) s = std::make_unique<Buffer>();
        s->upload(kernel.data(), N * sizeof(std::complex<double>));
        transform(s, scratch_, period, rows, false);
    }
    key_ = key;
}

std::vector<float> GlFft::convolve(const std::vector<float>& image, int width, int height, const diffraction::Psf& psf,
                                   double* offFrame) {
    const std::size_t pixels = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
    if (image.size() != pixels * 3) throw Error(ErrorKind::Runtime, "convolve: the image does not match its size");
    std::vector<float> out(pixels * 3, 0.0f);
    if (pixels == 0) return out;
    const auto [rx, ry] = diffraction::kernelReach(image, width, height, psf);
    // Linear convolution: a period of at least W + rx keeps what wraps around out of the frame.
    const int P = nextSmooth(width + rx), Q = nextSmooth(height + ry);
    if (P > kMaxSide || Q > kMaxSide) throw Error(ErrorKind::Runtime, "the frame is too large for the GL FFT");
    const std::size_t N = static_cast<std::size_t>(P) * Q;
    kernelSpectra(psf, width, height, P, Q);
    image_.upload(image.data(), image.size() * sizeof(float));
    frame_.upload(nullptr, pixels * sizeof(std::complex<double>));
    a_->upload(nullptr, N * sizeof(std::complex<double>));
    std::vector<std::complex<double>> frame(pixels);
    std::array<double, 3> in{}, kept{};
    for (std::size_t p = 0; p < pixels; ++p)
        for (std::size_t c = 0; c < 3; ++c) in[c] += image[p * 3 + c];
    // Red and green as one complex transform (r + i g), then blue.
    for (const auto [first, second] : {std::array<int, 2>{0, 1}, std::array<int, 2>{2, -1}}) {
        scatter_->use();
        scatter_->set("width", width);
        scatter_->set("period", P);
        scatter_->set("count", static_cast<int>(static_cast<std::size_t>(P) * height));
        scatter_->set("first", first);
        scatter_->set("second", second);
        a_->bind(0);
        image_.bind(1);
        dispatch(static_cast<std::size_t>(P) * height);
        checkGl("fft_scatter.comp");
        transform(a_, scratch_, P, Q, false, height);
        product_->use();
        product_->set("period", P);
        product_->set("rows", Q);
        product_->setDouble("scale", 1.0 / static_cast<double>(N));
        a_->bind(0);
        spectrum_[static_cast<std::size_t>(first)]->bind(1);
        spectrum_[static_cast<std::size_t>(second < 0 ? first : second)]->bind(2);
        dispatch(N);
        checkGl("spectrum_product.comp");
        transform(a_, scratch_, P, Q, true, height);
        gather_->use();
        gather_->set("width", width);
        gather_->set("period", P);
        gather_->set("count", static_cast<int>(pixels));
        a_->bind(0);
        frame_.bind(1);
        dispatch(pixels);
        checkGl("fft_gather.comp");
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        frame_.download(frame.data(), pixels * sizeof(std::complex<double>));
        for (std::size_t p = 0; p < pixels; ++p) {
            out[p * 3 + static_cast<std::size_t>(first)] = static_cast<float>(frame[p].real());
            kept[static_cast<std::size_t>(first)] += frame[p].real();
            if (second < 0) continue;
            out[p * 3 + static_cast<std::size_t>(second)] = static_cast<float>(frame[p].imag());
            kept[static_cast<std::size_t>(second)] += frame[p].imag();
        }
    }
    double off = 0.0;
    for (std::size_t c = 0; c < 3; ++c) off += std::max(0.0, in[c] * flux_[c] - kept[c]);
    if (offFrame) *offFrame += off;
    return out;
}

} // namespace ff::gpu
