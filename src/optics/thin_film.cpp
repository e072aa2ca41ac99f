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

double stackReflectanceComplex(double n0, const std::vector<FilmLayer>& layers, double nSub, double cosI,
                               double lambdaNm, bool pPolarised) {
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

// Both polarisations when every layer and the substrate have real angles (no total internal
// reflection anywhere): each layer matrix is [[cos d, i sin d / eta], [i eta sin d, cos d]] with real
// d and eta, and products of matrices of the form [[a, i b], [i c, e]] keep that form, so the whole
// computation is real. Returns false when some angle is complex.
bool stackReflectanceReal(double n0, const std::vector<FilmLayer>& layers, double nSub, double cosI, double lambdaNm,
                          double& rsOut, double& rpOut) {
    const double inv2 = n0 * n0 * (1.0 - cosI * cosI);
    if (nSub * nSub <= inv2) return false;
    for (const FilmLayer& l : layers)
        if (l.n * l.n <= inv2) return false;
    // m = [[a, i b], [i c, e]] per polarisation.
    double as = 1, bs = 0, cs = 0, es = 1, ap = 1, bp = 0, cp = 0, ep = 1;
    for (const FilmLayer& l : layers) {
        const double c = std::sqrt(1.0 - inv2 / (l.n * l.n));
        const double delta = 2.0 * std::numbers::pi * l.n * l.thicknessNm * c / lambdaNm;
        const double cd = std::cos(delta), sd = std::sin(delta);
        const double etaS = l.n * c, etaP = l.n / c;
        // [[a, ib], [ic, e]] x [[cd, i sd/eta], [i eta sd, cd]]
        const double as2 = as * cd - bs * etaS * sd, bs2 = as * sd / etaS + bs * cd;
        const double cs2 = cs * cd + es * etaS * sd, es2 = es * cd - cs * sd / etaS;
        as = as2, bs = bs2, cs = cs2, es = es2;
        const double ap2 = ap * cd - bp * etaP * sd, bp2 = ap * sd / etaP + bp * cd;
        const double cp2 = cp * cd + ep * etaP * sd, ep2 = ep * cd - cp * sd / etaP;
        ap = ap2, bp = bp2, cp = cp2, ep = ep2;
    }
    const double cSub = std::sqrt(1.0 - inv2 / (nSub * nSub));
    // B = a + i b eta_sub, C = i c + e eta_sub;  r = (eta0 B - C) / (eta0 B + C).
    auto R = [](double eta0, double etaSub, double a, double b, double c, double e) {
        const double reN = eta0 * a - e * etaSub, imN = eta0 * b * etaSub - c;
        const double reD = eta0 * a + e * etaSub, imD = eta0 * b * etaSub + c;
        return (reN * reN + imN * imN) / (reD * reD + imD * imD);
    };
    rsOut = R(n0 * cosI, nSub * cSub, as, bs, cs, es);
    rpOut = R(n0 / cosI, nSub / cSub, ap, bp, cp, ep);
    return true;
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
    double rs = 0.0, rp = 0.0;
    if (cosI > 0.0 && stackReflectanceReal(n0, layers, nSub, cosI, lambdaNm, rs, rp))
        return std::min(1.0, 0.5 * (rs + rp));
    return 0.5 * (stackReflectanceComplex(n0, layers, nSub, cosI, lambdaNm, false) +
                  stackReflectanceComplex(n0, layers, nSub, cosI, lambdaNm, true));
}

FilmReflectanceTable::FilmReflectanceTable(double n0, std::vector<FilmLayer> layers, double nSub, double lambdaNm)
    : n0_(n0), nSub_(nSub), lambdaNm_(lambdaNm), layers_(std::move(layers)) {
    double nMin = nSub;
    for (const FilmLayer& l : layers_) nMin = std::min(nMin, l.n);
    uStar2_ = nMin < n0 ? 1.0 - (nMin / n0) * (nMin / n0) : 0.0;
    const double sMax = std::sqrt(1.0 - uStar2_);
    // The first knot one interval above the branch point when there is one: at s = 0 itself the
    // p-polarised admittance n / cos of the least-index medium is infinite (its limit is finite).
    const int first = uStar2_ > 0.0 ? 1 : 0;
    sStep_ = sMax / (kIntervals + first);
    sLo_ = first * sStep_;
    auto R = [&](double s) { return filmReflectance(n0_, layers_, nSub_, std::sqrt(s * s + uStar2_), lambdaNm_); };
    knots_.resize(2 * (kIntervals + 1));
    const double d = 1e-4 * sStep_; // central differences for the slopes: O(d^2) and 1e-16 / d
    for (int k = 0; k <= kIntervals; ++k) {
        const double s = sLo_ + k * sStep_;
        knots_[2 * k] = R(s);
        // One-sided (second order) where the other side leaves the range: at s = 0 and s_max.
        double slope = 0.0;
        if (s - d < 0.0)
            slope = (-3.0 * R(s) + 4.0 * R(s + d) - R(s + 2 * d)) / (2 * d);
        else if (s + d > sMax)
            slope = (3.0 * R(s) - 4.0 * R(s - d) + R(s - 2 * d)) / (2 * d);
        else
            slope = (R(s + d) - R(s - d)) / (2 * d);
        knots_[2 * k + 1] = sStep_ * slope;
    }
}

double FilmReflectanceTable::operator()(double cosI) const {
    const double s2 = cosI * cosI - uStar2_;
    const double x = (s2 > 0.0 ? std::sqrt(s2) - sLo_ : -1.0) / sStep_;
    if (!(x >= 0.0) || knots_.empty()) return filmReflectance(n0_, layers_, nSub_, cosI, lambdaNm_);
    const int k = std::min(static_cast<int>(x), kIntervals - 1);
    const double t = x - k;
    const double* p = &knots_[2 * static_cast<std::size_t>(k)];
    // Hermite basis on [0, 1]: values p[0], p[2], slopes (per interval) p[1], p[3].
    const double t2 = t * t, t3 = t2 * t;
    return std::min(1.0, (2 * t3 - 3 * t2 + 1) * p[0] + (t3 - 2 * t2 + t) * p[1] + (-2 * t3 + 3 * t2) * p[2] +
                             (t3 - t2) * p[3]);
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
