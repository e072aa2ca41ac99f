#include "optics/thin_film.h"

#include "optics/glass_catalog.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

namespace ff::optics {

namespace {

using cplx = std::complex<double>;

// cos(theta) in a medium of index n from the invariant n0 sin(theta0) (complex beyond the critical
// angle, on the branch with a non-negative imaginary part: an evanescent, decaying wave).
cplx cosIn(double n, double n0SinI) {
    const cplx c = std::sqrt(cplx(1.0 - (n0SinI / n) * (n0SinI / n), 0.0));
    return c.imag() < 0.0 ? -c : c;
}

double stackReflectance(double n0, const std::vector<FilmLayer>& layers, double nSub, double cosI, double lambdaNm,
                        bool pPolarised) {
    const double sinI = std::sqrt(std::max(0.0, 1.0 - cosI * cosI));
    const double inv = n0 * sinI;
    auto eta = [&](double n, cplx c) { return pPolarised ? cplx(n) / c : cplx(n) * c; };
    cplx m00(1.0), m01(0.0), m10(0.0), m11(1.0);
    for (const FilmLayer& l : layers) {
        const cplx c = cosIn(l.n, inv);
        const cplx e = eta(l.n, c);
        const cplx delta = 2.0 * std::numbers::pi * l.n * l.thicknessNm * c / lambdaNm;
        const cplx cd = std::cos(delta), sd = std::sin(delta), i(0.0, 1.0);
        const cplx a00 = cd, a01 = i * sd / e, a10 = i * e * sd, a11 = cd;
        const cplx n00 = m00 * a00 + m01 * a10, n01 = m00 * a01 + m01 * a11;
        const cplx n10 = m10 * a00 + m11 * a10, n11 = m10 * a01 + m11 * a11;
        m00 = n00, m01 = n01, m10 = n10, m11 = n11;
    }
    const cplx etaSub = eta(nSub, cosIn(nSub, inv));
    const cplx eta0 = eta(n0, cplx(cosI, 0.0));
    const cplx B = m00 + m01 * etaSub, C = m10 + m11 * etaSub;
    const cplx r = (eta0 * B - C) / (eta0 * B + C);
    return std::min(1.0, std::norm(r));
}

} // namespace

double fresnelReflectance(double n1, double n2, double cosI) {
    const double sinT = n1 / n2 * std::sqrt(std::max(0.0, 1.0 - cosI * cosI));
    if (sinT >= 1.0) return 1.0; // total internal reflection
    const double cosT = std::sqrt(1.0 - sinT * sinT);
    const double rs = (n1 * cosI - n2 * cosT) / (n1 * cosI + n2 * cosT);
    const double rp = (n2 * cosI - n1 * cosT) / (n2 * cosI + n1 * cosT);
    return 0.5 * (rs * rs + rp * rp);
}

double filmReflectance(double n0, const std::vector<FilmLayer>& layers, double nSub, double cosI, double lambdaNm) {
    if (layers.empty()) return fresnelReflectance(n0, nSub, cosI);
    return 0.5 * (stackReflectance(n0, layers, nSub, cosI, lambdaNm, false) +
                  stackReflectance(n0, layers, nSub, cosI, lambdaNm, true));
}

std::vector<FilmLayer> filmLayers(const CoatingSpec& spec, double lambdaNm) {
    std::vector<FilmLayer> out;
    out.reserve(spec.layers.size());
    for (const CoatingLayer& l : spec.layers) {
        const GlassEntry& m = GlassCatalog::builtin().get(l.material, {});
        out.push_back({m.dispersion.index(lambdaNm), l.waves * spec.lambda0Nm / m.dispersion.index(spec.lambda0Nm)});
    }
    return out;
}

double coatedReflectance(const CoatingSpec& spec, double n1, double n2, double cosI, double lambdaNm) {
    if (spec.bare()) return fresnelReflectance(n1, n2, cosI);
    std::vector<FilmLayer> layers = filmLayers(spec, lambdaNm);
    if (n1 > n2) std::reverse(layers.begin(), layers.end()); // arriving from the glass side
    return filmReflectance(n1, layers, n2, cosI, lambdaNm);
}

} // namespace ff::optics
