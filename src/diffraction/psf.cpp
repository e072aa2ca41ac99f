#include "diffraction/psf.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "diffraction/fftw.h"
#include "optics/paraxial.h"
#include "trace/aperture.h"
#include "trace/sequential_tracer.h"
#include "trace/traced_flare.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fftw3.h>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>

namespace ff::diffraction {

namespace {

// The exit pupil's distance to the sensor over its diameter (the stop's image at the working opening),
// else the paraxial f-number.
double workingFNumber(const optics::FirstOrder& fo) {
    const double distance = fo.imageDistance - fo.exitPupilZ;
    return std::isfinite(fo.exitPupilZ) && fo.exitPupilDiameter > 0.0 ? std::abs(distance) / fo.exitPupilDiameter
                                                                      : fo.fNumber;
}

} // namespace

Aperture apertureOf(const optics::Lens& lens) {
    const optics::FirstOrder fo = optics::analyzeFirstOrder(lens, lines::d);
    const trace::Iris iris = trace::LensAtWavelength(lens, lines::d, std::numeric_limits<double>::quiet_NaN(),
                                                     trace::LensAtWavelength::Films::Exact)
                                 .iris;
    Aperture a;
    a.blades = iris.blades;
    a.rotationRad = iris.rotationRad;
    a.fNumber = workingFNumber(fo);
    if (!(a.fNumber > 0.0) || !std::isfinite(a.fNumber))
        throw Error(ErrorKind::Input, "the lens has no finite working f-number: its diffraction is not defined");
    // The PSF on the sensor is the exit pupil's: an anamorphic whose cylinders stand in front of the
    // stop (a front attachment) has a round exit pupil and the same image-space cone in both sections,
    // so the same PSF; one whose sections' cones differ would need an elliptical one.
    if (!lens.rotationallySymmetric()) {
        const double nX =
            workingFNumber(optics::analyzeFirstOrder(optics::sectionOf(lens, optics::Section::X), lines::d));
        if (!(std::abs(nX - a.fNumber) <= 1e-6 * a.fNumber))
            throw Error(ErrorKind::Input, "the lens's working f-number differs between its sections (x " +
                                              text::fixed(nX, 4) + ", y " + text::fixed(a.fNumber, 4) +
                                              "): its PSF on the sensor is elliptical, which the diffraction does not "
                                              "make yet");
    }
    return a;
}

namespace {

constexpr int kMaxTransform = 16384;
constexpr double kJoin = 0.2, kJoinEnd = 0.4;    // of the transform's reach: the near field's blend into the far
constexpr double kJoinAberrated[2] = {0.6, 0.9}; // the same with a traced wavefront or vignetting
constexpr int kAliases = 4;                      // neighbouring periods subtracted each way
constexpr double kDirtTaper = 0.3; // of the shortest reach: the dirt's diffraction tapered from it to 0 there

// The PSF's samples in the transform's order (sample (i, j) at offset ((i, j) mod F) x spacing from
// the light, +y up the rows): share of the flux per sample, summing to 1.
std::vector<double> intensity(const Aperture& aperture, double lambdaNm, double spacingMm, int F,
                              const Wavefront& wavefront, const Transmission& open, const PupilMask* mask) {
    if (F < 64 || F > kMaxTransform || F % 2 != 0)
        throw Error(ErrorKind::Usage, "the PSF's transform must be even, 64 to " + std::to_string(kMaxTransform));
    const double lambdaN = lambdaNm * 1e-6 * aperture.fNumber; // mm
    const double Q = F * spacingMm / lambdaN;                  // pupil samples across its diameter
    if (!(Q >= 32.0) || Q > 0.5 * F * (1.0 + 1e-9))
        throw Error(ErrorKind::Usage, "the PSF's sampling puts " + text::fixed(Q, 1) +
                                          " samples across the pupil: it needs 32 to half the transform");
    // The pupil, centred on sample (0, 0) (wrapped), +y up the rows: each sample's share of its
    // square inside the iris and let through by the rest of the lens (coverage), 8 x 8 points per
    // sample on the iris's edge and 4 x 4 on the vignetting's (a staircase edge would draw faint
    // spikes along the grid's axes). With a wavefront W the pupil function is coverage x
    // exp(2 pi i W / lambda).
    const trace::Iris iris(aperture.blades, aperture.rotationRad, 0.5 * Q);
    const std::size_t N = static_cast<std::size_t>(F), H = N / 2 + 1;
    const int reach = static_cast<int>(std::ceil(iris.circumradius)) + 1;
    auto index = [&](int x, int y) {
        return static_cast<std::size_t>((y + F) % F) * N + static_cast<std::size_t>((x + F) % F);
    };
    const double unit = 1.0 / iris.radius;
    const int row = 2 * reach + 1;
    auto at = [&](int x, int y) { return static_cast<std::size_t>(y + reach) * row + (x + reach); };
    std::vector<double> coverage(static_cast<std::size_t>(row) * row, 0.0);
    auto fraction = [](int n, double x, double y, auto&& inside) {
        int count = 0;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) count += inside(x + (i + 0.5) / n - 0.5, y + (j + 0.5) / n - 0.5);
        return count / double(n * n);
    };
    for (int y = -reach; y <= reach; ++y)
        for (int x = -reach; x <= reach; ++x) {
            const double m = iris.margin(x, y);
            coverage[at(x, y)] = std::abs(m) >= 0.75
                                     ? (m > 0.0 ? 1.0 : 0.0)
                                     : fraction(8, x, y, [&](double a, double b) { return iris.margin(a, b) >= 0.0; });
        }
    if (open) {
        std::vector<char> through(coverage.size(), 0);
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x)
                if (coverage[at(x, y)] > 0.0) through[at(x, y)] = open(x * unit, y * unit);
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x) {
                double& c = coverage[at(x, y)];
                if (c <= 0.0) continue;
                const char t = through[at(x, y)];
                const bool edge =
                    (x > -reach && through[at(x - 1, y)] != t) || (x < reach && through[at(x + 1, y)] != t) ||
                    (y > -reach && through[at(x, y - 1)] != t) || (y < reach && through[at(x, y + 1)] != t);
                c *= edge ? fraction(4, x, y, [&](double a, double b) { return open(a * unit, b * unit); }) : double(t);
            }
    }
    if (mask && !mask->empty()) {
        const double toMask = 1.0 / iris.circumradius;
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x)
                if (double& c = coverage[at(x, y)]; c > 0.0) c *= mask->at(x * toMask, y * toMask);
    }
    double power = 0.0;
    std::vector<double> I(N * N);
    if (!wavefront && !open) {
        auto in = fftwArray<double>(N * N);
        auto out = fftwArray<fftw_complex>(N * H);
        std::fill(in.get(), in.get() + N * N, 0.0);
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x) {
                const double v = coverage[at(x, y)];
                in.get()[index(x, y)] = v;
                power += v * v;
            }
        const Plan plan([&] { return fftw_plan_dft_r2c_2d(F, F, in.get(), out.get(), FFTW_ESTIMATE); });
        fftw_execute(plan.plan);
        // |X_k|^2 / (F^2 sum |p|^2) sums to 1 (Parseval); the r2c transform holds kx <= F/2, the rest
        // is the conjugate at (-ky, -kx).
        const double norm = 1.0 / (double(F) * F * power);
        for (std::size_t ky = 0; ky < N; ++ky)
            for (std::size_t kx = 0; kx < N; ++kx) {
                const fftw_complex& z = kx < H ? out.get()[ky * H + kx] : out.get()[((N - ky) % N) * H + (N - kx)];
                I[ky * N + kx] = (z[0] * z[0] + z[1] * z[1]) * norm;
            }
        return I;
    }
    auto field = fftwArray<fftw_complex>(N * N);
    std::fill(field.get()[0], field.get()[0] + 2 * N * N, 0.0);
    const double toRadians = 2.0 * std::numbers::pi / (lambdaNm * 1e-6);
    std::vector<double> phase(static_cast<std::size_t>(row) * row, NAN);
    double step = 0.0; // the largest phase change between neighbouring open samples, radians
    for (int y = -reach; y <= reach; ++y)
        for (int x = -reach; x <= reach; ++x) {
            const double v = coverage[at(x, y)];
            if (v <= 0.0) continue;
            const std::size_t k = at(x, y);
            const double p = phase[k] = wavefront ? toRadians * wavefront(x * unit, y * unit) : 0.0;
            if (x > -reach && !std::isnan(phase[k - 1])) step = std::max(step, std::abs(p - phase[k - 1]));
            if (y > -reach && !std::isnan(phase[k - row])) step = std::max(step, std::abs(p - phase[k - row]));
            field.get()[index(x, y)][0] = v * std::cos(p);
            field.get()[index(x, y)][1] = v * std::sin(p);
            power += v * v;
        }
    if (step >= std::numbers::pi)
        throw Error(ErrorKind::Input, "the wavefront's phase changes by " + text::fixed(step / std::numbers::pi, 2) +
                                          " pi between pupil samples: the PSF's transform is too small for it");
    if (!(power > 0.0)) throw Error(ErrorKind::Input, "the lens lets no light through the iris at this field");
    const Plan plan([&] { return fftw_plan_dft_2d(F, F, field.get(), field.get(), FFTW_FORWARD, FFTW_ESTIMATE); });
    fftw_execute(plan.plan);
    const double norm = 1.0 / (double(F) * F * power);
    for (std::size_t k = 0; k < N * N; ++k)
        I[k] = (field.get()[k][0] * field.get()[k][0] + field.get()[k][1] * field.get()[k][1]) * norm;
    return I;
}

} // namespace

SampledPsf sampledPsf(const Aperture& aperture, double lambdaNm, double spacingMm, int transform,
                      const Wavefront& wavefront, const Transmission& open, const PupilMask* mask) {
    const std::vector<double> I = intensity(aperture, lambdaNm, spacingMm, transform, wavefront, open, mask);
    const int F = transform;
    SampledPsf psf;
    psf.size = F;
    psf.spacingMm = spacingMm;
    psf.value.resize(I.size());
    for (int r = 0; r < F; ++r)
        for (int c = 0; c < F; ++c)
            psf.value[static_cast<std::size_t>(r) * F + c] =
                I[static_cast<std::size_t>((r + F / 2) % F) * F + static_cast<std::size_t>((c + F / 2) % F)];
    return psf;
}

namespace {

// Pixels of S x S samples: the intensity convolved with the pixel's box, exactly for a band-limited
// intensity sampled at its Nyquist rate or finer: its transform times sinc(pi p f) per axis
// (p f = q S / F at frequency index q), back, times S^2 (samples per pixel). Sampled at the pixels'
// centres (every S-th sample from the light) the sum is exactly the flux on the grid: the sinc is zero
// at the multiples of 1 / p that sampling at the pitch would fold onto 0.
std::vector<double> binned(std::vector<double> I, int F, int S) {
    const std::size_t N = static_cast<std::size_t>(F), H = N / 2 + 1;
    auto spectrum = fftwArray<fftw_complex>(N * H);
    auto field = fftwArray<double>(N * N);
    std::copy(I.begin(), I.end(), field.get());
    {
        const Plan plan([&] { return fftw_plan_dft_r2c_2d(F, F, field.get(), spectrum.get(), FFTW_ESTIMATE); });
        fftw_execute(plan.plan);
    }
    auto sinc = [&](std::size_t q) {
        const double f = (q <= N / 2 ? double(q) : double(q) - F) * S / F;
        return f == 0.0 ? 1.0 : std::sin(std::numbers::pi * f) / (std::numbers::pi * f);
    };
    std::vector<double> hx(H), hy(N);
    for (std::size_t q = 0; q < H; ++q) hx[q] = sinc(q);
    for (std::size_t q = 0; q < N; ++q) hy[q] = sinc(q);
    const double scale = double(S) * S / (double(F) * F);
    for (std::size_t qy = 0; qy < N; ++qy)
        for (std::size_t qx = 0; qx < H; ++qx) {
            const double h = hy[qy] * hx[qx] * scale;
            spectrum.get()[qy * H + qx][0] *= h;
            spectrum.get()[qy * H + qx][1] *= h;
        }
    {
        const Plan plan([&] { return fftw_plan_dft_c2r_2d(F, F, spectrum.get(), field.get(), FFTW_ESTIMATE); });
        fftw_execute(plan.plan);
    }
    std::copy(field.get(), field.get() + N * N, I.begin());
    return I;
}

// The wavelengths and their linear-sRGB weights: negative (out-of-gamut) weights clipped and each
// channel's weights summing to 1, so each channel's PSF carries the light's flux in that channel. A
// channel no wavelength reaches takes them equally.
std::vector<std::array<double, 3>> channelWeights(const PsfSettings& settings, std::vector<double>& wavelengthsNm) {
    std::vector<std::array<double, 3>> weights;
    if (settings.wavelengthsNm.empty()) {
        trace::colourWeights(8, wavelengthsNm, weights);
    } else {
        wavelengthsNm = settings.wavelengthsNm;
        for (double l : wavelengthsNm) weights.push_back(trace::linearSrgb(l));
    }
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (auto& w : weights) sum += (w[c] = std::max(0.0, w[c]));
        for (auto& w : weights) w[c] = sum > 0.0 ? w[c] / sum : 1.0 / double(weights.size());
    }
    return weights;
}

// One wavelength's kernel binned over pixels, its reach, samples per pixel, its far field and its
// value where the far field takes over, over the centre.
struct WavelengthKernel {
    std::vector<double> kernel; ///< (2 radius + 1)^2, rows down
    int radius = 0, binning = 0;
    double edge = 0.0;
    FarField far;             ///< this wavelength's alone (weights 1)
    std::vector<double> dirt; ///< what the dirt adds to the kernel (its layout); empty: clean
};

WavelengthKernel wavelengthKernel(const Aperture& aperture, const PsfSettings& settings, double lambdaNm) {
    const int F = settings.transform;
    WavelengthKernel k;
    k.far = farField(aperture, settings.pitchMm, {lambdaNm}, {{1.0, 1.0, 1.0}});
    const double lambdaN = lambdaNm * 1e-6 * aperture.fNumber;
    // S samples per pixel, at most lambda N / 2 apart (the intensity's Nyquist rate).
    // S and K (below) have no prime factor above 7: the transform's size K S stays fast.
    const double samples = std::ceil(settings.pitchMm / (0.5 * lambdaN) - 1e-9);
    // A whole number K >= 4 of pixels per period (K S samples, K even, about `transform`), so that
    // the pixels' centres tile the period and sum to its flux exactly. Pixels over ~2 000 lambda N
    // wide (the period over kMaxTransform samples): the PSF is the light's own pixel.
    if (4.0 * samples > kMaxTransform) {
        k.binning = static_cast<int>(std::min(samples, 1e9));
        k.radius = 0;
        k.kernel = {1.0};
        return k;
    }
    const int S = fastSize(std::max(1, static_cast<int>(samples)));
    k.binning = S;
    // With a wavefront, the pupil gets Q = T / (2 S') samples across (S' = pitch / (lambda N / 2)
    // rounded up to S): at least 8 |grad W| / lambda keeps the phase step under pi / 2.
    const PupilFunction pupil = settings.pupil ? settings.pupil(lambdaNm) : PupilFunction{};
    const double spacing = settings.pitchMm / S, needed = 8.0 * pupil.maxSlopeMm / (lambdaNm * 1e-6);
    const int period = std::max(F, static_cast<int>(std::ceil(needed * lambdaN / spacing)));
    const double half = 0.5 * period / S;
    const int K = 2 * fastSize(std::max(2, static_cast<int>(period > F ? std::ceil(half) : std::round(half))));
    const int T = K * S;
    if (T > kMaxTransform && (pupil.opd || pupil.open))
        throw Error(ErrorKind::Input, "the lens's aberrations at this field (a spot of " +
                                          text::fixed(2.0 * aperture.fNumber * pupil.maxSlopeMm * 1e3, 0) +
                                          " um) need a PSF transform over " + std::to_string(kMaxTransform) +
                                          " samples");
    if (T > kMaxTransform) {
        k.radius = 0;
        k.kernel = {1.0};
        return k;
    }
    const std::vector<double> P =
        binned(intensity(aperture, lambdaNm, spacing, T, pupil.opd, pupil.open, nullptr), T, S);
    // Dirt: what it changes in the transform's intensity (the same sampling's errors cancel in the
    // difference), added over the transform's reach when the wavelengths are combined.
    std::vector<double> dirt;
    if (settings.mask && !settings.mask->empty()) {
        dirt = binned(intensity(aperture, lambdaNm, spacing, T, pupil.opd, pupil.open, settings.mask.get()), T, S);
        for (std::size_t i = 0; i < dirt.size(); ++i) dirt[i] -= P[i];
    }
    // The transform's intensity is periodic (K pixels): it holds the light's own PSF plus its
    // neighbouring periods' tails, strongest along the spikes. Those tails are the far field's,
    // subtracted (periods within kAliases each way: what is left of the 1 / r^2 sum is under 1 % of
    // the spike where the far field takes over). The near field is kept to kJoin of the reach and
    // blends into the far field by kJoinEnd.
    const int R = K / 4;
    k.radius = R;
    const int w = 2 * R + 1;
    std::vector<double>& b = k.kernel;
    b.assign(static_cast<std::size_t>(w) * w, 0.0);
    // An aberrated PSF (a traced wavefront, vignetting) spreads over up to its reach (the transform is
    // sized for its spot): kept to kJoinAberrated of it, where only the edges' spikes remain.
    const bool aberrated = pupil.opd || pupil.open;
    const double start = (aberrated ? kJoinAberrated[0] : kJoin) * R,
                 end = (aberrated ? kJoinAberrated[1] : kJoinEnd) * R;
    double centre = 0.0, joint = 0.0;
    for (int my = -R; my <= R; ++my)
        for (int mx = -R; mx <= R; ++mx) {
            const double r = std::hypot(mx, my), t = (r - start) / (end - start);
            const double near = t <= 0.0 ? 1.0 : t >= 1.0 ? 0.0 : std::pow(std::cos(0.5 * std::numbers::pi * t), 2);
            double v = 0.0;
            if (near > 0.0) {
                // Pixel rows run down, sample rows up.
                double p =
                    P[static_cast<std::size_t>((-my * S + T) % T) * T + static_cast<std::size_t>((mx * S + T) % T)];
                for (int j = -kAliases; j <= kAliases; ++j)
                    for (int i = -kAliases; i <= kAliases; ++i)
                        if (i != 0 || j != 0) p -= k.far.at(0, mx + i * K, my + j * K);
                v = near * std::max(0.0, p); // rounding in the transforms can leave tiny negatives
            }
            if (near < 1.0) v += (1.0 - near) * k.far.at(0, mx, my);
            if (!dirt.empty())
                k.dirt.push_back(
                    dirt[static_cast<std::size_t>((-my * S + T) % T) * T + static_cast<std::size_t>((mx * S + T) % T)]);
            if (mx == 0 && my == 0) centre = v;
            if (t >= 0.0) joint = std::max(joint, v);
            b[static_cast<std::size_t>(my + R) * w + (mx + R)] = v;
        }
    k.edge = centre > 0.0 ? joint / centre : 0.0;
    return k;
}

// The share of channel c's flux the far field carries outside the square |dx|, |dy| <= inner: summed
// over the pixels to 4 inner (at least 64) from the light, in closed form beyond (each line's
// profile integrated across, times 2 / r along its two rays; 2 pi airy / r).
double farOutside(const FarField& far, int c, int inner) {
    const int reach = std::max(64, 4 * inner);
    double sum = 0.0;
    for (int y = -reach; y <= reach; ++y)
        for (int x = -reach; x <= reach; ++x)
            if ((std::abs(x) > inner || std::abs(y) > inner) && double(x) * x + double(y) * y <= double(reach) * reach)
                sum += far.at(c, x, y);
    const std::size_t k = static_cast<std::size_t>(c);
    for (const FarField::Line& l : far.lines) {
        double across = 0.0;
        for (double v : l.profile[k]) across += v * l.step;
        sum += 2.0 * across / reach;
    }
    return sum + 2.0 * std::numbers::pi * far.airy[k] / reach;
}

} // namespace

Psf pixelPsf(const Aperture& aperture, const PsfSettings& settings) {
    if (!(settings.pitchMm > 0.0)) throw Error(ErrorKind::Usage, "the PSF needs a positive pixel pitch");
    Psf out;
    const std::vector<std::array<double, 3>> weights = channelWeights(settings, out.wavelengthsNm);
    const std::size_t W = out.wavelengthsNm.size();
    std::vector<WavelengthKernel> kernels(W);
    tbb::parallel_for(std::size_t(0), W,
                      [&](std::size_t i) { kernels[i] = wavelengthKernel(aperture, settings, out.wavelengthsNm[i]); });
    for (const WavelengthKernel& k : kernels) {
        out.binning.push_back(k.binning);
        out.radius = std::max(out.radius, k.radius);
        out.edge = std::max(out.edge, k.edge);
    }
    out.far = farField(aperture, settings.pitchMm, out.wavelengthsNm, weights);
    // The dirt's diffraction to the shortest reach, tapered from kDirtTaper of it: every wavelength's
    // ends at the same radius (no coloured rim).
    int dirtReach = out.radius;
    for (const WavelengthKernel& k : kernels) dirtReach = std::min(dirtReach, k.radius);
    const int w = out.width();
    for (int c = 0; c < 3; ++c) {
        std::vector<double> sum(static_cast<std::size_t>(w) * w, 0.0);
        for (std::size_t i = 0; i < W; ++i) {
            // A wavelength's kernel reaching less far than the square: its far field beyond.
            const int R = kernels[i].radius, wi = 2 * R + 1;
            for (int y = -out.radius; y <= out.radius; ++y)
                for (int x = -out.radius; x <= out.radius; ++x) {
                    const double v = std::abs(x) <= R && std::abs(y) <= R
                                         ? kernels[i].kernel[static_cast<std::size_t>(y + R) * wi + (x + R)]
                                         : kernels[i].far.at(0, x, y);
                    sum[static_cast<std::size_t>(y + out.radius) * w + (x + out.radius)] += weights[i][c] * v;
                }
            if (kernels[i].dirt.empty() || dirtReach == 0) continue;
            for (int y = -dirtReach; y <= dirtReach; ++y)
                for (int x = -dirtReach; x <= dirtReach; ++x) {
                    const double d = (std::hypot(x, y) - kDirtTaper * dirtReach) / ((1.0 - kDirtTaper) * dirtReach);
                    const double keep = d <= 0.0   ? 1.0
                                        : d >= 1.0 ? 0.0
                                                   : std::pow(std::cos(0.5 * std::numbers::pi * d), 2);
                    sum[static_cast<std::size_t>(y + out.radius) * w + (x + out.radius)] +=
                        weights[i][c] * keep * kernels[i].dirt[static_cast<std::size_t>(y + R) * wi + (x + R)];
                }
        }
        for (double& v : sum) v = std::max(0.0, v);
        double kept = 0.0;
        for (double v : sum) kept += v;
        const double missing = 1.0 - kept - farOutside(out.far, c, out.radius);
        out.outside = std::max(out.outside, std::abs(missing));
        sum[static_cast<std::size_t>(out.radius) * w + out.radius] += missing;
        out.channel[c].assign(sum.begin(), sum.end());
    }
    return out;
}

} // namespace ff::diffraction
