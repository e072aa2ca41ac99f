#include "ghosts/ghost_fit.h"

#include "core/error.h"
#include "core/text.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace ff::ghosts {

const char* toString(Profile p) {
    return p == Profile::Gaussian ? "gaussian" : "cos2";
}

Profile profileNamed(std::string_view name, std::string_view what) {
    for (const Profile p : {Profile::Gaussian, Profile::Cos2})
        if (name == toString(p)) return p;
    throw Error(ErrorKind::Usage, std::string(what) + " is gaussian or cos2, got " + text::quoted(std::string(name)));
}

namespace {

// Unit-peak profile along one axis: the separable factor of profileValue.
double profileFactor(Profile p, double w, double t) {
    if (p == Profile::Gaussian) return std::exp(-0.5 * t * t / (w * w));
    if (std::abs(t) >= w) return 0.0;
    const double c = std::cos(0.5 * std::numbers::pi * t / w);
    return c * c;
}

} // namespace

double profileValue(Profile p, double wr, double wt, double u, double v) {
    return profileFactor(p, wr, u) * profileFactor(p, wt, v);
}

double profileArea(Profile p, double wr, double wt) {
    return p == Profile::Gaussian ? 2.0 * std::numbers::pi * wr * wt : wr * wt;
}

namespace {

// A polygon with energy in sensor mm (q) and its vertices' mean; false where it has no energy or the
// mean lies beyond maxRadius (> 0).
bool sensorPolygon(const ShapedPolygons& ps, const ShapedPolygons::Poly& poly, const trace::ImageFrame& frame,
                   double maxRadius, std::vector<glm::dvec2>& q, glm::dvec2& mean) {
    if (!(poly.energy > 0.0) || poly.count == 0) return false;
    q.resize(poly.count);
    mean = glm::dvec2(0.0);
    for (std::uint32_t i = 0; i < poly.count; ++i) {
        const glm::vec2& v = ps.vertices[poly.first + i];
        q[i] = frame.pixelToSensor(v.x, v.y);
        mean += q[i];
    }
    mean /= static_cast<double>(poly.count);
    return !(maxRadius > 0.0 && glm::dot(mean, mean) > maxRadius * maxRadius);
}

} // namespace

PolygonMoments polygonMoments(const ShapedPolygons& ps, const trace::ImageFrame& frame, double maxRadius) {
    // Sums about a reference point (the first vertex), in mm, so that the second moments of a small
    // ghost far from the axis do not cancel.
    std::array<double, 6> s{}; // energy, x, y, xx, yy, xy
    glm::dvec2 ref(0.0);
    bool haveRef = false;
    std::vector<glm::dvec2> q;
    for (const ShapedPolygons::Poly& poly : ps.polys) {
        glm::dvec2 mean;
        if (!sensorPolygon(ps, poly, frame, maxRadius, q, mean)) continue;
        if (!haveRef) ref = q[0], haveRef = true;
        // Green's theorem over the edges (x_i, y_i) -> (x_j, y_j), c = x_i y_j - x_j y_i:
        // A = sum c / 2, int x = sum (x_i + x_j) c / 6, int x^2 = sum (x_i^2 + x_i x_j + x_j^2) c / 12,
        // int xy = sum (x_i y_j + 2 x_i y_i + 2 x_j y_j + x_j y_i) c / 24.
        double a = 0.0, ix = 0.0, iy = 0.0, ixx = 0.0, iyy = 0.0, ixy = 0.0;
        for (std::uint32_t i = 0; i < poly.count; ++i) {
            const glm::dvec2 p = q[i] - ref, r = q[(i + 1) % poly.count] - ref;
            const double c = p.x * r.y - r.x * p.y;
            a += c;
            ix += (p.x + r.x) * c;
            iy += (p.y + r.y) * c;
            ixx += (p.x * p.x + p.x * r.x + r.x * r.x) * c;
            iyy += (p.y * p.y + p.y * r.y + r.y * r.y) * c;
            ixy += (p.x * r.y + 2.0 * p.x * p.y + 2.0 * r.x * r.y + r.x * p.y) * c;
        }
        a *= 0.5;
        const double e = poly.energy;
        // A sliver whose area vanishes in rounding is a point mass at its vertices' mean.
        double size2 = 0.0;
        for (std::uint32_t i = 0; i < poly.count; ++i) size2 = std::max(size2, glm::dot(q[i] - mean, q[i] - mean));
        if (!(std::abs(a) > 1e-12 * size2) || size2 == 0.0) {
            const glm::dvec2 m = mean - ref;
            s[0] += e, s[1] += e * m.x, s[2] += e * m.y, s[3] += e * m.x * m.x, s[4] += e * m.y * m.y,
                s[5] += e * m.x * m.y;
            continue;
        }
        const double d = e / a; // density, with the orientation's sign
        s[0] += e;
        s[1] += d * ix / 6.0;
        s[2] += d * iy / 6.0;
        s[3] += d * ixx / 12.0;
        s[4] += d * iyy / 12.0;
        s[5] += d * ixy / 24.0;
    }
    PolygonMoments m;
    if (!(s[0] > 0.0)) return m;
    m.energy = s[0];
    const double cx = s[1] / s[0], cy = s[2] / s[0];
    m.centroidX = ref.x + cx;
    m.centroidY = ref.y + cy;
    m.mxx = std::max(0.0, s[3] / s[0] - cx * cx);
    m.myy = std::max(0.0, s[4] / s[0] - cy * cy);
    m.mxy = s[5] / s[0] - cx * cy;
    return m;
}

namespace {

// The ghost's irradiance (flux per pixel) on a local square frame around the centroid.
struct LocalImage {
    trace::ImageFrame frame;
    std::vector<double> flux;
};

// Sum of squared differences between the flux-normalised profile and the image, pixel by pixel (the
// profile sampled at pixel centres times the pixel area). The profile is separable, a R_y C_x with
// the image's rows radial and columns tangential, so
//   sum (a R_y C_x - I_yx)^2 = a^2 (sum R^2)(sum C^2) - 2 a sum_y R_y (sum_x C_x I_yx) + sum I^2,
// and with one width held, the other's search costs one pass over a row or column of the image.
class Misfit {
  public:
    Misfit(const LocalImage& img, Profile p, double flux) : img_(img), p_(p), flux_(flux) {
        for (double v : img.flux) norm2_ += v * v;
    }
    double norm2() const { return norm2_; }

    /// Holds the tangential width: returns the misfit as a function of the radial one.
    auto radial(double wt) const {
        std::vector<double> c = columns(wt), u(rows());
        double c2 = 0.0;
        for (double v : c) c2 += v * v;
        for (std::size_t y = 0; y < u.size(); ++y) u[y] = dot(&img_.flux[y * c.size()], 1, c);
        return [this, c2, wt, u = std::move(u)](double wr) { return value(wr, wt, rowFactors(wr), u, c2); };
    }
    /// Holds the radial width: returns the misfit as a function of the tangential one.
    auto tangential(double wr) const {
        std::vector<double> r = rowFactors(wr), u(columnsCount());
        double r2 = 0.0;
        for (double v : r) r2 += v * v;
        for (std::size_t x = 0; x < u.size(); ++x) u[x] = dot(&img_.flux[x], u.size(), r);
        return [this, r2, wr, u = std::move(u)](double wt) { return value(wr, wt, columns(wt), u, r2); };
    }

  private:
    std::size_t rows() const { return static_cast<std::size_t>(img_.frame.height); }
    std::size_t columnsCount() const { return static_cast<std::size_t>(img_.frame.width); }
    std::vector<double> rowFactors(double wr) const {
        std::vector<double> r(rows());
        for (std::size_t y = 0; y < r.size(); ++y)
            r[y] = profileFactor(p_, wr,
                                 img_.frame.pixelToSensor(0.0, static_cast<double>(y) + 0.5).y - img_.frame.centreYMm);
        return r;
    }
    std::vector<double> columns(double wt) const {
        std::vector<double> c(columnsCount());
        for (std::size_t x = 0; x < c.size(); ++x)
            c[x] = profileFactor(p_, wt,
                                 img_.frame.pixelToSensor(static_cast<double>(x) + 0.5, 0.0).x - img_.frame.centreXMm);
        return c;
    }
    static double dot(const double* a, std::size_t stride, const std::vector<double>& b) {
        double s = 0.0;
        for (std::size_t i = 0; i < b.size(); ++i) s += a[i * stride] * b[i];
        return s;
    }
    // The misfit from the free axis's factors f, the held axis's projections u and its sum of squares.
    double value(double wr, double wt, const std::vector<double>& f, const std::vector<double>& u, double held2) const {
        const double a = img_.frame.pitchMm * img_.frame.pitchMm * flux_ / profileArea(p_, wr, wt);
        double f2 = 0.0, cross = 0.0;
        for (std::size_t i = 0; i < f.size(); ++i) f2 += f[i] * f[i], cross += f[i] * u[i];
        return std::max(0.0, a * a * f2 * held2 - 2.0 * a * cross + norm2_);
    }

    const LocalImage& img_;
    Profile p_;
    double flux_, norm2_ = 0.0;
};

// Golden-section search of f over log(x) in [lo, hi].
template <typename F>
double goldenLog(const F& f, double lo, double hi, int iterations) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = std::log(lo), b = std::log(hi);
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = f(std::exp(c)), fd = f(std::exp(d));
    for (int i = 0; i < iterations; ++i) {
        if (fc < fd) {
            b = d, d = c, fd = fc;
            c = b - g * (b - a);
            fc = f(std::exp(c));
        } else {
            a = c, c = d, fc = fd;
            d = a + g * (b - a);
            fd = f(std::exp(d));
        }
    }
    return std::exp(0.5 * (a + b));
}

ProfileFit fitProfile(const LocalImage& img, Profile p, double flux, double startR, double startT) {
    // Least squares over the two widths: alternate one-dimensional searches over a factor of 4
    // around the current value, three rounds (the misfit is smooth and unimodal near the moments).
    const Misfit misfit(img, p, flux);
    double wr = startR, wt = startT;
    for (int round = 0; round < 3; ++round) {
        wr = goldenLog(misfit.radial(wt), 0.5 * wr, 2.0 * wr, 24);
        wt = goldenLog(misfit.tangential(wr), 0.5 * wt, 2.0 * wt, 24);
    }
    ProfileFit f;
    f.widthR = wr;
    f.widthT = wt;
    f.peak = flux / profileArea(p, wr, wt);
    f.error = misfit.norm2() > 0.0 ? std::sqrt(misfit.radial(wt)(wr) / misfit.norm2()) : 0.0;
    return f;
}

} // namespace

GhostFit fitGhost(const ShapedPolygons& ps, const trace::ImageFrame& frame, const FitOptions& o) {
    GhostFit fit;
    const PolygonMoments m = polygonMoments(ps, frame, o.maxRadiusMm);
    if (!(m.energy > 0.0)) return fit;
    fit.flux = m.energy;
    fit.centroidX = m.centroidX;
    fit.centroidY = m.centroidY;
    fit.sigmaT = std::sqrt(m.mxx);
    fit.sigmaR = std::sqrt(m.myy);
    fit.covRT = m.mxy;

    // The ghost's image around the centroid; spreads below 1 micron are treated as 1 micron.
    const double sR = std::max(fit.sigmaR, 1e-3), sT = std::max(fit.sigmaT, 1e-3);
    LocalImage img;
    img.frame = {o.imageSize, o.imageSize, 2.0 * o.extentSigmas * std::max(sR, sT) / o.imageSize, fit.centroidX,
                 fit.centroidY};
    trace::CoverageRaster raster(img.frame);
    trace::RasterStats stats;
    std::vector<glm::dvec2> q;
    for (const ShapedPolygons::Poly& poly : ps.polys) {
        glm::dvec2 mean;
        if (!sensorPolygon(ps, poly, frame, o.maxRadiusMm, q, mean)) continue;
        for (glm::dvec2& p : q) p = img.frame.sensorToPixel(p.x, p.y);
        raster.polygon(q, poly.energy, stats);
    }
    img.flux = std::move(raster).release();
    fit.gaussian = fitProfile(img, Profile::Gaussian, m.energy, sR, sT);
    fit.cos2 = fitProfile(img, Profile::Cos2, m.energy, 2.766 * sR, 2.766 * sT);
    return fit;
}

} // namespace ff::ghosts
