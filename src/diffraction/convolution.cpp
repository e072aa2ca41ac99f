#include "diffraction/convolution.h"

#include "core/error.h"
#include "diffraction/fftw.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <mutex>

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

std::uint64_t kernelFingerprint(const Psf& psf) {
    std::uint64_t h = 14695981039346656037ull;
    const auto add = [&](const void* data, std::size_t bytes) {
        for (std::size_t i = 0; i < bytes; ++i) {
            h ^= static_cast<const unsigned char*>(data)[i];
            h *= 1099511628211ull;
        }
    };
    const auto addVector = [&](const auto& v) {
        const std::size_t n = v.size();
        add(&n, sizeof n);
        add(v.data(), n * sizeof(v[0]));
    };
    add(&psf.radius, sizeof psf.radius);
    for (const auto& c : psf.channel) addVector(c);
    add(psf.far.airy.data(), sizeof psf.far.airy);
    for (const FarField::Line& line : psf.far.lines) {
        const double header[] = {line.nx, line.ny, line.step, static_cast<double>(line.half)};
        add(header, sizeof header);
        for (const auto& c : line.profile) addVector(c);
    }
    return h;
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

void addOutsideLight(const Psf& psf, long long x, long long y, const std::array<double, 3>& flux, int width, int height,
                     std::vector<float>& out, double* offFrame) {
    if (width <= 0 || height <= 0) return;
    if (out.size() != static_cast<std::size_t>(width) * height * 3)
        throw Error(ErrorKind::Runtime, "addOutsideLight: the image does not match its size");
    const long long R = psf.radius;
    const int pw = psf.width();
    // The rows and columns the kernel reaches: the whole frame with a far field, else the square's.
    long long x0 = 0, x1 = width - 1, y0 = 0, y1 = height - 1;
    if (psf.far.empty()) {
        x0 = std::max(x0, x - R), x1 = std::min(x1, x + R);
        y0 = std::max(y0, y - R), y1 = std::min(y1, y + R);
    }
    std::vector<std::array<double, 3>> kept(static_cast<std::size_t>(height), std::array<double, 3>{});
    if (x0 <= x1 && y0 <= y1)
        tbb::parallel_for(static_cast<int>(y0), static_cast<int>(y1) + 1, [&](int py) {
            const long long dy = py - y;
            std::array<double, 3>& row = kept[static_cast<std::size_t>(py)];
            for (int px = static_cast<int>(x0); px <= x1; ++px) {
                const long long dx = px - x;
                const bool square = std::llabs(dx) <= R && std::llabs(dy) <= R;
                float* o = &out[(static_cast<std::size_t>(py) * width + px) * 3];
                for (int c = 0; c < 3; ++c) {
                    const std::size_t ch = static_cast<std::size_t>(c);
                    if (flux[ch] == 0.0) continue;
                    const double k = square ? psf.channel[ch][static_cast<std::size_t>((dy + R) * pw + (dx + R))]
                                            : psf.far.at(c, static_cast<double>(dx), static_cast<double>(dy));
                    o[c] += static_cast<float>(flux[ch] * k);
                    row[ch] += flux[ch] * k;
                }
            }
        });
    if (!offFrame) return;
    for (std::size_t c = 0; c < 3; ++c) {
        double whole = 1.0, in = 0.0;
        if (psf.far.empty()) {
            whole = 0.0;
            for (float v : psf.channel[c]) whole += v;
        }
        for (const std::array<double, 3>& row : kept) in += row[c];
        *offFrame += std::max(0.0, flux[c] * whole - in);
    }
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

// The smallest odd size >= n whose factors are 3, 5 and 7: as many rows keep the column
// transforms' strides off the powers of two that thrash the cache (a 3840 x 2187 transform takes
// 0.7 of the time of a 3840 x 2160 one on a 2-core machine).
int oddSize(int n) {
    for (int m = std::max(1, n);; ++m) {
        int r = m;
        for (int f : {3, 5, 7})
            while (r % f == 0) r /= f;
        if (r == 1) return m;
    }
}

constexpr int kFftThreads = 2;

// FFTW's real transforms in one precision: fftw_* (double) or fftwf_* (float).
template <class Real>
struct Fftw;
template <>
struct Fftw<double> {
    using Complex = fftw_complex;
    using PlanT = fftw_plan;
    static PlanT r2c(int h, int w, double* a) {
        return fftw_plan_dft_r2c_2d(h, w, a, reinterpret_cast<Complex*>(a), FFTW_ESTIMATE);
    }
    static PlanT c2r(int h, int w, double* a) {
        return fftw_plan_dft_c2r_2d(h, w, reinterpret_cast<Complex*>(a), a, FFTW_ESTIMATE);
    }
    static void forward(PlanT p, double* a) { fftw_execute_dft_r2c(p, a, reinterpret_cast<Complex*>(a)); }
    static void backward(PlanT p, double* a) { fftw_execute_dft_c2r(p, reinterpret_cast<Complex*>(a), a); }
    static void destroy(PlanT p) { fftw_destroy_plan(p); }
    static double* alloc(std::size_t n) { return fftw_alloc_real(n); }
    static void release(double* a) { fftw_free(a); }
};
template <>
struct Fftw<float> {
    using Complex = fftwf_complex;
    using PlanT = fftwf_plan;
    static PlanT r2c(int h, int w, float* a) {
        return threaded([&] { return fftwf_plan_dft_r2c_2d(h, w, a, reinterpret_cast<Complex*>(a), FFTW_ESTIMATE); });
    }
    static PlanT c2r(int h, int w, float* a) {
        return threaded([&] { return fftwf_plan_dft_c2r_2d(h, w, reinterpret_cast<Complex*>(a), a, FFTW_ESTIMATE); });
    }
    // The far field's transforms are large and few (one per channel and operand): each runs on
    // kFftThreads threads (a fixed count: the same plan, so the same bytes, on every machine).
    template <class Make>
    static PlanT threaded(Make make) {
        static const bool ready = fftwf_init_threads() != 0;
        if (ready) fftwf_plan_with_nthreads(kFftThreads);
        const PlanT p = make();
        if (ready) fftwf_plan_with_nthreads(1);
        return p;
    }
    static void forward(PlanT p, float* a) { fftwf_execute_dft_r2c(p, a, reinterpret_cast<Complex*>(a)); }
    static void backward(PlanT p, float* a) { fftwf_execute_dft_c2r(p, reinterpret_cast<Complex*>(a), a); }
    static void destroy(PlanT p) { fftwf_destroy_plan(p); }
    static float* alloc(std::size_t n) { return fftwf_alloc_real(n); }
    static void release(float* a) { fftwf_free(a); }
};

// The linear convolution of a frame's channel with a kernel reaching (kx, ky), by transforms of
// period (fastSize(W + kx), oddSize(H + ky)) in place (each row padded to Wp / 2 + 1 complex
// values): what wraps around the period falls outside the frame.
template <class Real>
class FftConvolution {
    using F = Fftw<Real>;

  public:
    struct Buffer {
        Real* p;
        /// Uninitialised (planning with FFTW_ESTIMATE does not touch it) unless zeroed.
        explicit Buffer(std::size_t n, bool zero = true) : p(F::alloc(n)) {
            if (!p) throw Error(ErrorKind::Runtime, "out of memory for the diffraction's transforms");
            if (zero) std::fill(p, p + n, Real(0));
        }
        ~Buffer() { F::release(p); }
        Buffer(const Buffer&) = delete;
        Buffer& operator=(const Buffer&) = delete;
    };

    FftConvolution(int width, int height, int kx, int ky)
        : W_(width), H_(height), Wp_(fastSize(width + kx)), Hp_(oddSize(height + ky)),
          row_(2 * (static_cast<std::size_t>(Wp_) / 2 + 1)) {
        Buffer a(size(), false);
        std::lock_guard<std::mutex> lock(fourier::fftwPlannerMutex());
        forward_ = F::r2c(Hp_, Wp_, a.p);
        backward_ = F::c2r(Hp_, Wp_, a.p);
        if (!forward_ || !backward_) throw Error(ErrorKind::Runtime, "FFTW could not plan a diffraction transform");
    }
    ~FftConvolution() {
        std::lock_guard<std::mutex> lock(fourier::fftwPlannerMutex());
        if (forward_) F::destroy(forward_);
        if (backward_) F::destroy(backward_);
    }
    FftConvolution(const FftConvolution&) = delete;
    FftConvolution& operator=(const FftConvolution&) = delete;

    int period() const { return Wp_; }
    int rows() const { return Hp_; }

    /// The kernel's spectrum: kernel(put) calls put(dx, dy, value) for its non-zero offsets
    /// (|dx| <= Wp - W, |dy| <= Hp - H: no further, or it would wrap around into the frame).
    template <class Kernel>
    std::unique_ptr<Buffer> spectrum(Kernel&& kernel) const {
        auto ker = std::make_unique<Buffer>(size());
        kernel([&](int dx, int dy, double v) {
            ker->p[static_cast<std::size_t>((dy + Hp_) % Hp_) * row_ + (dx + Wp_) % Wp_] += static_cast<Real>(v);
        });
        F::forward(forward_, ker->p);
        return ker;
    }

    /// Adds channel c of `image` (R, G, B interleaved) convolved with the kernel whose spectrum is
    /// `kernel` to `sum` (the same layout).
    void run(const std::vector<float>& image, int c, std::vector<double>& sum, const Buffer& kernel) const {
        Buffer img(size());
        for (int y = 0; y < H_; ++y)
            for (int x = 0; x < W_; ++x)
                img.p[static_cast<std::size_t>(y) * row_ + x] =
                    static_cast<Real>(image[(static_cast<std::size_t>(y) * W_ + x) * 3 + c]);
        F::forward(forward_, img.p);
        auto* I = reinterpret_cast<typename F::Complex*>(img.p);
        const auto* K = reinterpret_cast<const typename F::Complex*>(kernel.p);
        const Real scale = Real(1) / (static_cast<Real>(Wp_) * static_cast<Real>(Hp_));
        for (std::size_t k = 0; k < size() / 2; ++k) {
            const Real re = I[k][0] * K[k][0] - I[k][1] * K[k][1];
            const Real im = I[k][0] * K[k][1] + I[k][1] * K[k][0];
            I[k][0] = re * scale;
            I[k][1] = im * scale;
        }
        F::backward(backward_, img.p);
        for (int y = 0; y < H_; ++y)
            for (int x = 0; x < W_; ++x)
                sum[(static_cast<std::size_t>(y) * W_ + x) * 3 + c] += img.p[static_cast<std::size_t>(y) * row_ + x];
    }

  private:
    std::size_t size() const { return row_ * static_cast<std::size_t>(Hp_); }
    int W_, H_, Wp_, Hp_;
    std::size_t row_;
    typename F::PlanT forward_ = nullptr, backward_ = nullptr;
};

} // namespace

// The transforms of the last frame's size and PSF, and the kernel's spectra with them.
struct FftwConvolver::Kept {
    struct Key {
        std::uint64_t psf = 0;
        int width = 0, height = 0, kx = 0, ky = 0, rx = 0,
            ry = 0; ///< the near square's and the far field's periods' reach
        bool operator==(const Key&) const = default;
    };
    Key key;
    std::unique_ptr<FftConvolution<double>> near;
    std::unique_ptr<FftConvolution<float>> far; ///< null: no far field reaches the frame
    std::array<std::unique_ptr<FftConvolution<double>::Buffer>, 3> nearSpectrum;
    std::array<std::unique_ptr<FftConvolution<float>::Buffer>, 3> farSpectrum;

    Kept(const Key& k, const Psf& psf, bool withFar) : key(k) {
        const int W = k.width, H = k.height, R = psf.radius;
        near = std::make_unique<FftConvolution<double>>(W, H, k.kx, k.ky);
        // Each kernel over every offset that cannot wrap around its period into the frame (at least
        // the lights' reach): the same spectra serve any frame that needs these periods.
        const int nx = std::min({R, near->period() - W, W - 1}), ny = std::min({R, near->rows() - H, H - 1});
        tbb::parallel_for(0, 3, [&](int c) {
            const std::vector<float>& ch = psf.channel[static_cast<std::size_t>(c)];
            nearSpectrum[static_cast<std::size_t>(c)] = near->spectrum([&](auto&& put) {
                for (int dy = -ny; dy <= ny; ++dy)
                    for (int dx = -nx; dx <= nx; ++dx)
                        put(dx, dy, ch[static_cast<std::size_t>(dy + R) * psf.width() + (dx + R)]);
            });
        });
        if (!withFar) return;
        far = std::make_unique<FftConvolution<float>>(W, H, k.rx, k.ry);
        const int fx = std::min(W - 1, far->period() - W), fy = std::min(H - 1, far->rows() - H);
        // One channel at a time, each transform on FFTW's threads.
        for (int c = 0; c < 3; ++c)
            farSpectrum[static_cast<std::size_t>(c)] = far->spectrum(
                [&](auto&& put) { psf.far.forEach(c, fx, fy, R, [&](int dx, int dy, double v) { put(dx, dy, v); }); });
    }
};

FftwConvolver::FftwConvolver() = default;
FftwConvolver::~FftwConvolver() = default;

bool convolvesDirectly(const std::vector<float>& image, int width, int height, const Psf& psf) {
    const std::size_t lit =
        static_cast<std::size_t>(std::count_if(image.begin(), image.end(), [](float v) { return v != 0.0f; }));
    const auto [rx, ry] = kernelReach(image, width, height, psf);
    return direct(lit, width, height, rx, ry);
}

std::vector<float> FftwConvolver::convolve(const std::vector<float>& image, int width, int height, const Psf& psf,
                                           double* offFrame) {
    const std::size_t pixels = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
    if (image.size() != pixels * 3) throw Error(ErrorKind::Runtime, "convolve: the image does not match its size");
    std::vector<float> out(pixels * 3, 0.0f);
    if (pixels == 0) return out;
    const auto [rx, ry] = kernelReach(image, width, height, psf);
    std::array<double, 3> off{};
    const std::size_t lit =
        static_cast<std::size_t>(std::count_if(image.begin(), image.end(), [](float v) { return v != 0.0f; }));
    if (direct(lit, width, height, rx, ry)) {
        convolveDirect(image, width, height, psf, rx, ry, out, off);
        if (offFrame) *offFrame += off[0] + off[1] + off[2];
        return out;
    }
    // The PSF's square in double (the transforms' rounding spreads ~1e-16 of the lights' flux over
    // the frame; float's 1e-7 of a 60 000-valued source would show on a night plate); the far field
    // beyond it (under 1e-4 of the flux per pixel) in float, over the larger period it needs.
    const int R = psf.radius;
    const bool far = !psf.far.empty() && (rx > R || ry > R);
    // The periods (fastSize, oddSize) are the key, not the reach itself: frames whose lights reach
    // differently but need the same periods reuse the kernel's spectra.
    const Kept::Key key{kernelFingerprint(psf),
                        width,
                        height,
                        fastSize(width + std::min(R, rx)) - width,
                        oddSize(height + std::min(R, ry)) - height,
                        far ? fastSize(width + rx) - width : 0,
                        far ? oddSize(height + ry) - height : 0};
    if (!kept_ || !(kept_->key == key)) {
        kept_.reset();
        kept_ = std::make_unique<Kept>(key, psf, far);
    }
    std::vector<double> sum(pixels * 3, 0.0);
    tbb::parallel_for(
        0, 3, [&](int c) { kept_->near->run(image, c, sum, *kept_->nearSpectrum[static_cast<std::size_t>(c)]); });
    for (int c = 0; far && c < 3; ++c) kept_->far->run(image, c, sum, *kept_->farSpectrum[static_cast<std::size_t>(c)]);
    tbb::parallel_for(0, 3, [&](int c) {
        const std::vector<float>& k = psf.channel[static_cast<std::size_t>(c)];
        double in = 0.0, kept = 0.0, whole = 0.0;
        for (float v : k) whole += v;
        if (!psf.far.empty()) whole = 1.0;
        for (std::size_t p = 0; p < pixels; ++p) {
            in += image[p * 3 + c];
            kept += sum[p * 3 + c];
            out[p * 3 + c] = static_cast<float>(sum[p * 3 + c]);
        }
        off[static_cast<std::size_t>(c)] = std::max(0.0, in * whole - kept);
    });
    if (offFrame) *offFrame += off[0] + off[1] + off[2];
    return out;
}

std::vector<float> convolve(const std::vector<float>& image, int width, int height, const Psf& psf, double* offFrame) {
    return FftwConvolver().convolve(image, width, height, psf, offFrame);
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

std::vector<float>
sumOverTiles(const std::vector<float>& lights, int width, int height, int tilesX, int tilesY,
             const std::function<std::vector<float>(const std::vector<float>& tile, double x, double y)>& part) {
    std::vector<float> sum(lights.size(), 0.0f), tile(lights.size());
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            const int x0 = tx * width / tilesX, x1 = (tx + 1) * width / tilesX;
            const int y0 = ty * height / tilesY, y1 = (ty + 1) * height / tilesY;
            std::fill(tile.begin(), tile.end(), 0.0f);
            double flux = 0.0, cx = 0.0, cy = 0.0;
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const std::size_t p = (static_cast<std::size_t>(y) * width + x) * 3;
                    double s = 0.0;
                    for (int c = 0; c < 3; ++c) s += tile[p + c] = lights[p + c];
                    flux += s;
                    cx += s * (x + 0.5);
                    cy += s * (y + 0.5);
                }
            if (!(flux > 0.0)) continue;
            const std::vector<float> one = part(tile, cx / flux, cy / flux);
            for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += one[i];
        }
    return sum;
}

} // namespace ff::diffraction
