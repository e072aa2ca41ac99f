#include "image/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ff::image {

ImageError compareImages(const std::vector<float>& a, const std::vector<float>& ref) {
    ImageError e;
    double num = 0.0, den = 0.0, peak = 0.0, sa = 0.0, sr = 0.0;
    for (std::size_t i = 0; i < ref.size() && i < a.size(); ++i) {
        const double d = double(a[i]) - double(ref[i]);
        num += d * d;
        den += double(ref[i]) * ref[i];
        peak = std::max(peak, std::abs(double(ref[i])));
        e.maxAbs = std::max(e.maxAbs, std::abs(d));
        sa += a[i];
        sr += ref[i];
    }
    e.relativeL2 = den > 0.0 ? std::sqrt(num / den) : (num > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
    const double rms = ref.empty() ? 0.0 : std::sqrt(num / double(ref.size()));
    e.psnrDb = rms > 0.0 ? 20.0 * std::log10(peak / rms) : std::numeric_limits<double>::infinity();
    e.maxRelative = peak > 0.0 ? e.maxAbs / peak : 0.0;
    e.fluxRatio = sr != 0.0 ? sa / sr : 0.0;
    return e;
}

namespace {

std::vector<double> luminanceDifference(const std::vector<float>& a, const std::vector<float>& ref) {
    std::vector<double> d(ref.size() / 3);
    for (std::size_t p = 0; p < d.size(); ++p)
        d[p] = 0.2126 * (double(a[3 * p]) - ref[3 * p]) + 0.7152 * (double(a[3 * p + 1]) - ref[3 * p + 1]) +
               0.0722 * (double(a[3 * p + 2]) - ref[3 * p + 2]);
    return d;
}

} // namespace

std::vector<unsigned char> differencePicture(const std::vector<float>& a, const std::vector<float>& ref, double scale) {
    const std::vector<double> d = luminanceDifference(a, ref);
    std::vector<unsigned char> out(d.size() * 3);
    for (std::size_t p = 0; p < d.size(); ++p) {
        const double t = scale > 0.0 ? std::clamp(d[p] / scale, -1.0, 1.0) : 0.0;
        // White at 0; towards red (1, 0, 0) for t > 0, blue (0, 0.2, 1) for t < 0 (sRGB-ish).
        const double u = std::sqrt(std::abs(t)); // perceptually spreads small differences
        double r = 1.0, g = 1.0, b = 1.0;
        if (t > 0)
            g = 1.0 - u, b = 1.0 - u;
        else if (t < 0)
            r = 1.0 - u, g = 1.0 - 0.8 * u;
        out[3 * p] = static_cast<unsigned char>(std::lround(255.0 * r));
        out[3 * p + 1] = static_cast<unsigned char>(std::lround(255.0 * g));
        out[3 * p + 2] = static_cast<unsigned char>(std::lround(255.0 * b));
    }
    return out;
}

double differenceQuantile(const std::vector<float>& a, const std::vector<float>& ref, double q) {
    std::vector<double> d = luminanceDifference(a, ref);
    for (double& v : d) v = std::abs(v);
    if (d.empty()) return 0.0;
    const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * double(d.size() - 1));
    std::nth_element(d.begin(), d.begin() + static_cast<long>(k), d.end());
    return d[k];
}

} // namespace ff::image
