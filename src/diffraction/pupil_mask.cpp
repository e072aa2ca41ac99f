#include "diffraction/pupil_mask.h"

#include "core/error.h"
#include "core/text.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace ff::diffraction {

double PupilMask::at(double u, double v) const {
    if (empty()) return 1.0;
    // Sample coordinates: centres at integers.
    const double x = 0.5 * (u + 1.0) * size - 0.5, y = 0.5 * (1.0 - v) * size - 0.5;
    if (!(x > -1.0 && y > -1.0 && x < size && y < size)) return 1.0;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    auto value = [&](int i, int j) {
        i = std::clamp(i, 0, size - 1), j = std::clamp(j, 0, size - 1);
        return double(transmittance[static_cast<std::size_t>(j) * size + i]);
    };
    return (1.0 - fy) * ((1.0 - fx) * value(x0, y0) + fx * value(x0 + 1, y0)) +
           fy * ((1.0 - fx) * value(x0, y0 + 1) + fx * value(x0 + 1, y0 + 1));
}

namespace {

// SplitMix64 and a double in [0, 1) from its top 53 bits: the same sequence on every machine and
// standard library (std's distributions are not).
struct Random {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

// Multiplies the raster by 1 - opacity x coverage of the points within halfWidth of the shape (the
// distance `distance` gives, raster pixels), antialiased over a pixel, inside the box [x0, x1] x [y0, y1]
// (pupil units).
template <class Distance>
void stamp(PupilMask& m, double x0, double y0, double x1, double y1, double halfWidth, double opacity,
           Distance&& distance) {
    const double px = 2.0 / m.size; // pupil units per raster pixel
    const int i0 = std::max(0, static_cast<int>(std::floor((x0 + 1.0) / px)) - 1);
    const int i1 = std::min(m.size - 1, static_cast<int>(std::ceil((x1 + 1.0) / px)) + 1);
    const int j0 = std::max(0, static_cast<int>(std::floor((1.0 - y1) / px)) - 1);
    const int j1 = std::min(m.size - 1, static_cast<int>(std::ceil((1.0 - y0) / px)) + 1);
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const double u = (i + 0.5) * px - 1.0, v = 1.0 - (j + 0.5) * px;
            const double cover = std::clamp((halfWidth - distance(u, v)) / px + 0.5, 0.0, 1.0);
            if (cover > 0.0) m.transmittance[static_cast<std::size_t>(j) * m.size + i] *= float(1.0 - opacity * cover);
        }
}

} // namespace

PupilMask proceduralDirt(std::uint64_t seed, double density, int size) {
    if (!(density > 0.0) || !(density <= 100.0))
        throw Error(ErrorKind::Usage,
                    "the dirt's density must be above 0 and at most 100, got " + text::roundTrip(density));
    if (size < 16 || size > 8192) throw Error(ErrorKind::Usage, "the dirt's raster must be 16 to 8192 samples");
    PupilMask m;
    m.size = size;
    m.transmittance.assign(static_cast<std::size_t>(size) * size, 1.0f);
    m.key = "dirt " + std::to_string(seed) + "," + text::roundTrip(density) + " " + std::to_string(size);
    Random rng{seed};
    auto inDisc = [&](double& x, double& y) {
        do {
            x = 2.0 * rng.uniform() - 1.0, y = 2.0 * rng.uniform() - 1.0;
        } while (x * x + y * y > 1.0);
    };
    const int specks = static_cast<int>(std::lround(80.0 * density));
    for (int k = 0; k < specks; ++k) {
        double x, y;
        inDisc(x, y);
        const double u = rng.uniform();
        const double r = 0.003 + 0.017 * u * u * u, opacity = 0.5 + 0.5 * rng.uniform();
        stamp(m, x - r, y - r, x + r, y + r, r, opacity, [&](double a, double b) { return std::hypot(a - x, b - y); });
    }
    const int scratches = std::max(1, static_cast<int>(std::lround(3.0 * density)));
    for (int k = 0; k < scratches; ++k) {
        double x, y;
        inDisc(x, y);
        double angle = 2.0 * std::numbers::pi * rng.uniform();
        const double length = 0.3 + 0.6 * rng.uniform(), half = 0.5 * (0.001 + 0.002 * rng.uniform());
        const double opacity = 0.3 + 0.5 * rng.uniform();
        for (int s = 0; s < 4; ++s) { // four segments, each bent a little
            const double x1 = x + 0.25 * length * std::cos(angle), y1 = y + 0.25 * length * std::sin(angle);
            const double dx = x1 - x, dy = y1 - y, len2 = dx * dx + dy * dy;
            const double ax = x, ay = y;
            stamp(m, std::min(x, x1) - half, std::min(y, y1) - half, std::max(x, x1) + half, std::max(y, y1) + half,
                  half, opacity, [&](double a, double b) {
                      const double t = std::clamp(((a - ax) * dx + (b - ay) * dy) / len2, 0.0, 1.0);
                      return std::hypot(a - ax - t * dx, b - ay - t * dy);
                  });
            x = x1, y = y1;
            angle += 0.2 * (rng.uniform() - 0.5);
        }
    }
    return m;
}

PupilMask maskFromImage(const std::vector<float>& pixels, int width, int height, int channels, int r, int g, int b,
                        const std::string& name) {
    if (width < 1 || height < 1 || channels < 1 || r < 0 || r >= channels || g >= channels || b >= channels ||
        pixels.size() != static_cast<std::size_t>(width) * height * channels)
        throw Error(ErrorKind::Input, SourceLocation{name}, "the aperture mask has no pixels to read");
    PupilMask m;
    m.size = std::min(width, height);
    m.transmittance.resize(static_cast<std::size_t>(m.size) * m.size);
    const int ox = (width - m.size) / 2, oy = (height - m.size) / 2;
    std::uint64_t hash = 1469598103934665603ull; // FNV-1a over the values' bits
    for (int j = 0; j < m.size; ++j)
        for (int i = 0; i < m.size; ++i) {
            const float* p = &pixels[(static_cast<std::size_t>(j + oy) * width + (i + ox)) * channels];
            const double v = g >= 0 && b >= 0 ? 0.2126 * p[r] + 0.7152 * p[g] + 0.0722 * p[b] : p[r];
            if (!std::isfinite(v))
                throw Error(ErrorKind::Input, SourceLocation{name},
                            "the aperture mask has a non-finite value at pixel (" + std::to_string(i + ox) + ", " +
                                std::to_string(j + oy) + ")");
            const float t = static_cast<float>(std::clamp(v, 0.0, 1.0));
            m.transmittance[static_cast<std::size_t>(j) * m.size + i] = t;
            std::uint32_t bits;
            static_assert(sizeof bits == sizeof t);
            std::memcpy(&bits, &t, sizeof t);
            hash = (hash ^ bits) * 1099511628211ull;
        }
    m.key = "mask " + std::to_string(m.size) + " " + std::to_string(hash);
    return m;
}

PupilMask combine(const PupilMask& a, const PupilMask& b) {
    if (a.empty()) return b;
    if (b.empty()) return a;
    const PupilMask& big = a.size >= b.size ? a : b;
    const PupilMask& other = a.size >= b.size ? b : a;
    PupilMask m = big;
    for (int j = 0; j < m.size; ++j)
        for (int i = 0; i < m.size; ++i) {
            const double u = 2.0 * (i + 0.5) / m.size - 1.0, v = 1.0 - 2.0 * (j + 0.5) / m.size;
            m.transmittance[static_cast<std::size_t>(j) * m.size + i] *= static_cast<float>(other.at(u, v));
        }
    m.key = a.key + " x " + b.key;
    return m;
}

} // namespace ff::diffraction
