#include "ghosts/ghost_fit.h"

#include "trace/bundle_moments.h"
#include "trace/flare_raster.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ff::ghosts {

const char* toString(Profile p) {
    return p == Profile::Gaussian ? "gaussian" : "cos2";
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

// The traced irradiance (flux per pixel) on a local square frame around the centroid.
struct LocalImage {
    trace::ImageFrame frame;
    std::vector<double> flux;
};

// Sum of squared differences between the flux-normalised profile and the image, pixel by pixel
// (the profile sampled at pixel centres times the pixel area). The profile is separable and the
// image's axes are the radial (rows) and tangential (columns) ones, so it is sampled once per row
// and once per column.
double misfit(const LocalImage& img, Profile p, double flux, double wr, double wt) {
    const double a = img.frame.pitchMm * img.frame.pitchMm * flux / profileArea(p, wr, wt);
    std::vector<double> rows(static_cast<std::size_t>(img.frame.height)),
        columns(static_cast<std::size_t>(img.frame.width));
    for (int y = 0; y < img.frame.height; ++y)
        rows[y] = a * profileFactor(p, wr, img.frame.pixelToSensor(0.0, y + 0.5).y - img.frame.centreYMm);
    for (int x = 0; x < img.frame.width; ++x)
        columns[x] = profileFactor(p, wt, img.frame.pixelToSensor(x + 0.5, 0.0).x - img.frame.centreXMm);
    double sum = 0.0;
    for (int y = 0; y < img.frame.height; ++y) {
        const double* line = img.flux.data() + static_cast<std::size_t>(y) * img.frame.width;
        for (int x = 0; x < img.frame.width; ++x) {
            const double d = rows[y] * columns[x] - line[x];
            sum += d * d;
        }
    }
    return sum;
}

// Golden-section search of f over log(x) in [lo, hi].
template <typename F>
double goldenLog(F f, double lo, double hi, int iterations) {
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

ProfileFit fitProfile(const LocalImage& img, Profile p, double flux, double startR, double startT, double imageNorm2) {
    // Least squares over the two widths: alternate one-dimensional searches over a factor of 4
    // around the current value, three rounds (the misfit is smooth and unimodal near the moments).
    double wr = startR, wt = startT;
    for (int round = 0; round < 3; ++round) {
        wr = goldenLog([&](double x) { return misfit(img, p, flux, x, wt); }, 0.5 * wr, 2.0 * wr, 24);
        wt = goldenLog([&](double x) { return misfit(img, p, flux, wr, x); }, 0.5 * wt, 2.0 * wt, 24);
    }
    ProfileFit f;
    f.widthR = wr;
    f.widthT = wt;
    f.peak = flux / profileArea(p, wr, wt);
    f.error = imageNorm2 > 0.0 ? std::sqrt(misfit(img, p, flux, wr, wt) / imageNorm2) : 0.0;
    return f;
}

} // namespace

GhostFit fitGhost(const trace::Bundle& b, const std::vector<trace::RayResult>& c,
                  const std::vector<trace::RayResult>& k, double scale, const FitOptions& o,
                  const trace::BundleMoments* moments) {
    const BundlePart part{&b, &c, &k};
    return fitGhost(std::span<const BundlePart>(&part, 1), scale, o, moments);
}

GhostFit fitGhost(std::span<const BundlePart> parts, double scale, const FitOptions& o,
                  const trace::BundleMoments* moments) {
    GhostFit fit;
    trace::BundleMoments m;
    if (moments) {
        m = *moments;
    } else {
        std::vector<trace::BundleMoments> each;
        for (const BundlePart& p : parts)
            each.push_back(trace::measureBundle(*p.centres, *p.centreHits, scale, o.maxRadiusMm));
        m = trace::combineMoments(each);
    }
    fit.survivingFraction = m.launched ? double(m.surviving) / double(m.launched) : 0.0;
    if (m.energy <= 0.0) return fit;
    const double e = m.energy;
    fit.flux = e;
    fit.centroidX = m.centroidX;
    fit.centroidY = m.centroidY;
    fit.sigmaT = std::sqrt(m.mxx);
    fit.sigmaR = std::sqrt(m.myy);
    fit.covRT = m.mxy;

    // The traced image around the centroid; spreads below 1 micron are treated as 1 micron.
    const double sR = std::max(fit.sigmaR, 1e-3), sT = std::max(fit.sigmaT, 1e-3);
    LocalImage img;
    img.frame = {o.imageSize, o.imageSize, 2.0 * o.extentSigmas * std::max(sR, sT) / o.imageSize, fit.centroidX,
                 fit.centroidY};
    img.flux.assign(static_cast<std::size_t>(o.imageSize) * o.imageSize, 0.0);
    trace::RasterStats stats;
    for (const BundlePart& p : parts) {
        // The rays drawn into the fit image are the ones that counted (see FitOptions::maxRadiusMm).
        std::vector<trace::RayResult> cc = *p.centreHits;
        if (o.maxRadiusMm > 0.0)
            for (auto& r : cc)
                if (r.status == optics::RayStatus::Ok &&
                    r.sensorPoint.x * r.sensorPoint.x + r.sensorPoint.y * r.sensorPoint.y >
                        o.maxRadiusMm * o.maxRadiusMm)
                    r.status = optics::RayStatus::Missed;
        trace::rasterizeCells(*p.centres, cc, *p.cornerHits, scale, img.frame, img.flux, stats);
    }
    double norm2 = 0.0;
    for (double v : img.flux) norm2 += v * v;

    fit.gaussian = fitProfile(img, Profile::Gaussian, e, sR, sT, norm2);
    fit.cos2 = fitProfile(img, Profile::Cos2, e, 2.766 * sR, 2.766 * sT, norm2);
    return fit;
}

} // namespace ff::ghosts
