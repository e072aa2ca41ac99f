#include "diffraction/far_field.h"

#include "core/error.h"
#include "trace/aperture.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::diffraction {

namespace {

constexpr double kProfileStep = 1.0 / 32.0; // pixels
constexpr double kProfileReach = 24.0;      // pixels across the line

double sinc2(double x) {
    if (std::abs(x) < 1e-8) return 1.0;
    const double s = std::sin(x) / x;
    return s * s;
}

// The unit pixel's footprint across a line of unit tangent (tx, ty): the length of the pixel's chord
// along the line at transverse offset s from its centre (a trapezoid of area 1).
double chord(double s, double tx, double ty) {
    const double a = std::max(std::abs(tx), std::abs(ty)), b = std::min(std::abs(tx), std::abs(ty));
    const double x = std::abs(s), inner = 0.5 * (a - b), outer = 0.5 * (a + b);
    if (x >= outer) return 0.0;
    if (x <= inner) return 1.0 / a;
    return (outer - x) / (a * b);
}

// Int chord(s) sinc^2(pi L (d - s) / beta) ds over the pixel (Simpson, with at least 8 steps per
// fringe), pixels.
double acrossPixel(double d, double L, double beta, double tx, double ty) {
    const double a = std::max(std::abs(tx), std::abs(ty)), b = std::min(std::abs(tx), std::abs(ty));
    const double outer = 0.5 * (a + b);
    // A fringe under 1/256 of a pixel (a tiny plate on a large sensor): sinc^2 is beta / L times a delta.
    if (beta / L < 1.0 / 256.0) return beta / L * chord(d, tx, ty);
    const double h0 = std::min(beta / (8.0 * L), 1.0 / 64.0);
    const int n = 2 * static_cast<int>(std::ceil(outer / h0));
    const double h = 2.0 * outer / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double s = -outer + i * h;
        const double f = chord(s, tx, ty) * sinc2(std::numbers::pi * L * (d - s) / beta);
        sum += f * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
    }
    return sum * h / 3.0;
}

} // namespace

double FarField::at(int c, double dx, double dy) const {
    const double r2 = dx * dx + dy * dy;
    if (r2 < 0.25) return 0.0;
    double v = airy[static_cast<std::size_t>(c)] / (r2 * std::sqrt(r2));
    for (const Line& l : lines) {
        const double rho = dx * l.nx + dy * l.ny, d = dy * l.nx - dx * l.ny;
        const double u = d / l.step + l.half;
        if (!(u >= 0.0 && u <= 2.0 * l.half)) continue;
        const std::vector<double>& f = l.profile[static_cast<std::size_t>(c)];
        const std::size_t i = std::min(static_cast<std::size_t>(u), f.size() - 2);
        const double t = u - static_cast<double>(i);
        v += (f[i] + t * (f[i + 1] - f[i])) * rho * rho / (r2 * r2);
    }
    return v;
}

void FarField::forEach(int c, int rx, int ry, int inner,
                       const std::function<void(int dx, int dy, double share)>& add) const {
    auto outside = [&](int x, int y) { return std::abs(x) > inner || std::abs(y) > inner; };
    const std::size_t k = static_cast<std::size_t>(c);
    if (airy[k] > 0.0)
        for (int y = -ry; y <= ry; ++y)
            for (int x = -rx; x <= rx; ++x)
                if (outside(x, y)) {
                    const double r2 = double(x) * x + double(y) * y;
                    add(x, y, airy[k] / (r2 * std::sqrt(r2)));
                }
    for (const Line& l : lines) {
        FarField one;
        one.lines = {l};
        // Along the line's major axis, the pixels within the profile's reach across it.
        const bool alongX = std::abs(l.nx) >= std::abs(l.ny);
        const int m = alongX ? rx : ry, other = alongX ? ry : rx;
        const double slope = alongX ? l.ny / l.nx : l.nx / l.ny;
        const int band = static_cast<int>(std::ceil(l.reach() / std::max(std::abs(l.nx), std::abs(l.ny)))) + 1;
        for (int a = -m; a <= m; ++a) {
            const double centre = a * slope;
            const int b0 = std::max(-other, static_cast<int>(std::floor(centre)) - band);
            const int b1 = std::min(other, static_cast<int>(std::ceil(centre)) + band);
            for (int b = b0; b <= b1; ++b) {
                const int x = alongX ? a : b, y = alongX ? b : a;
                if (outside(x, y)) add(x, y, one.at(c, x, y));
            }
        }
    }
}

FarField farField(const Aperture& aperture, double pitchMm, const std::vector<double>& wavelengthsNm,
                  const std::vector<std::array<double, 3>>& weights) {
    if (!(pitchMm > 0.0) || !(aperture.fNumber > 0.0) || weights.size() != wavelengthsNm.size())
        throw Error(ErrorKind::Runtime, "farField: a pitch, an f-number and a weight per wavelength are needed");
    FarField far;
    const double pi = std::numbers::pi;
    // The pupil in units of its diameter D (the equal-area circle's, as the f-number's).
    if (aperture.blades < 3) {
        for (std::size_t i = 0; i < wavelengthsNm.size(); ++i) {
            const double beta = wavelengthsNm[i] * 1e-6 * aperture.fNumber / pitchMm;
            for (int c = 0; c < 3; ++c) far.airy[static_cast<std::size_t>(c)] += weights[i][c] * beta / (pi * pi * pi);
        }
        return far;
    }
    const int n = aperture.blades;
    const trace::Iris iris(n, aperture.rotationRad, 0.5);
    const double L = 2.0 * iris.circumradius * std::sin(pi / n), A = pi / 4.0;
    // Edges with parallel normals (k and k + n/2 for even n) share a line; the pupil's +y is up, the
    // pixels' down.
    const int count = n % 2 == 0 ? n / 2 : n, perLine = n % 2 == 0 ? 2 : 1;
    for (int k = 0; k < count; ++k) {
        const double phi = aperture.rotationRad + (k + 0.5) * 2.0 * pi / n;
        FarField::Line line;
        line.nx = std::cos(phi);
        line.ny = -std::sin(phi);
        line.step = kProfileStep;
        line.half = static_cast<int>(std::lround(kProfileReach / kProfileStep));
        const double tx = -line.ny, ty = line.nx;
        for (auto& p : line.profile) p.assign(static_cast<std::size_t>(2 * line.half + 1), 0.0);
        for (std::size_t i = 0; i < wavelengthsNm.size(); ++i) {
            const double beta = wavelengthsNm[i] * 1e-6 * aperture.fNumber / pitchMm;
            const double scale = perLine * L * L / (4.0 * pi * pi * A);
            for (int j = 0; j <= 2 * line.half; ++j) {
                const double d = std::abs(j - line.half) / double(line.half); // of the reach
                const double end = d <= 0.5 ? 1.0 : std::pow(std::cos(std::numbers::pi * (d - 0.5)), 2);
                const double h = end * scale * acrossPixel((j - line.half) * line.step, L, beta, tx, ty);
                for (int c = 0; c < 3; ++c)
                    line.profile[static_cast<std::size_t>(c)][static_cast<std::size_t>(j)] += weights[i][c] * h;
            }
        }
        far.lines.push_back(std::move(line));
    }
    return far;
}

} // namespace ff::diffraction
