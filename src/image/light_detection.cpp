#include "image/light_detection.h"

#include "core/error.h"
#include "core/text.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace ff::image {

DetectionSettings parseThreshold(const std::string& t) {
    DetectionSettings s;
    auto number = [&](std::string_view v) {
        const auto x = text::parseNumber(v);
        if (!x || !std::isfinite(*x))
            throw Error(ErrorKind::Usage,
                        "expected --threshold VALUE, max:FRACTION or p:PERCENTILE, got " + text::quoted(t));
        return *x;
    };
    if (t.rfind("max:", 0) == 0) {
        s.mode = ThresholdMode::RelativeToMax;
        s.value = number(std::string_view(t).substr(4));
        if (s.value <= 0.0 || s.value > 1.0)
            throw Error(ErrorKind::Usage, "--threshold max:F needs 0 < F <= 1, got " + text::quoted(t));
    } else if (t.rfind("p:", 0) == 0) {
        s.mode = ThresholdMode::Percentile;
        s.value = number(std::string_view(t).substr(2));
        if (s.value <= 0.0 || s.value >= 100.0)
            throw Error(ErrorKind::Usage, "--threshold p:P needs 0 < P < 100, got " + text::quoted(t));
    } else {
        s.value = number(t);
        if (s.value <= 0.0) throw Error(ErrorKind::Usage, "--threshold must be positive, got " + text::quoted(t));
    }
    return s;
}

namespace {

// Union-find over pixel indices.
struct Components {
    std::vector<std::uint32_t> parent;
    explicit Components(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    }
    void unite(std::uint32_t a, std::uint32_t b) {
        a = find(a), b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
};

} // namespace

namespace {

// Each pixel's luminance of its non-negative RGB (0 where a channel is NaN or infinite), counting those
// and the pixels with a negative channel, and the largest, into rep.
std::vector<float> pixelLuminances(const Plate& plate, DetectionReport& rep) {
    const std::size_t n = plate.pixelCount();
    std::vector<float> lum(n, 0.0f);
    for (std::size_t p = 0; p < n; ++p) {
        const double r = plate.value(p, plate.r), g = plate.value(p, plate.g), b = plate.value(p, plate.b);
        if (!std::isfinite(r) || !std::isfinite(g) || !std::isfinite(b)) {
            ++rep.nonFinite;
            continue;
        }
        const double l = luminance(std::max(0.0, r), std::max(0.0, g), std::max(0.0, b));
        if (r < 0.0 || g < 0.0 || b < 0.0) ++rep.negative;
        lum[p] = static_cast<float>(l);
        rep.maxLuminance = std::max(rep.maxLuminance, l);
    }
    return lum;
}

// The luminance threshold the settings ask for, kept strictly positive (above 0 every pixel would count).
double thresholdFor(const std::vector<float>& lum, const DetectionSettings& s, double maxLuminance) {
    double threshold = 0.0;
    switch (s.mode) {
    case ThresholdMode::Absolute:
        threshold = s.value;
        break;
    case ThresholdMode::RelativeToMax:
        threshold = s.value * maxLuminance;
        break;
    case ThresholdMode::Percentile: {
        std::vector<float> sorted(lum);
        const auto k = static_cast<std::size_t>(std::clamp(s.value / 100.0, 0.0, 1.0) * double(lum.size() - 1));
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(k), sorted.end());
        threshold = sorted[k];
        break;
    }
    }
    return std::max(threshold, 1e-12);
}

} // namespace

DetectionReport detectLights(const Plate& plate, const DetectionSettings& s) {
    DetectionReport rep;
    const std::size_t n = plate.pixelCount();
    const std::vector<float> lum = pixelLuminances(plate, rep);
    rep.threshold = thresholdFor(lum, s, rep.maxLuminance);
    const int W = plate.width, H = plate.height;
    Components comp(n);
    std::vector<char> bright(n, 0);
    if (s.lightImage) rep.lightRgb.assign(n * 3, 0.0f);
    for (std::size_t p = 0; p < n; ++p) {
        bright[p] = lum[p] > rep.threshold;
        if (bright[p] && s.lightImage)
            for (int c = 0; c < 3; ++c)
                rep.lightRgb[p * 3 + c] = std::max(0.0f, plate.value(p, c == 0 ? plate.r : c == 1 ? plate.g : plate.b));
    }
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * W + x;
            if (!bright[p]) continue;
            ++rep.brightPixels;
            if (plate.a >= 0 && plate.value(p, plate.a) == 0.0f) ++rep.emissiveZeroAlpha;
            // Neighbours already visited: left, and the three above.
            if (x > 0 && bright[p - 1]) comp.unite(static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(p - 1));
            if (y > 0)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx;
                    if (xx < 0 || xx >= W) continue;
                    const std::size_t q = static_cast<std::size_t>(y - 1) * W + xx;
                    if (bright[q]) comp.unite(static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(q));
                }
        }
    // Component extents, to know which ones to split.
    struct Extent {
        int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    };
    std::map<std::uint32_t, Extent> extents;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * W + x;
            if (!bright[p]) continue;
            Extent& e = extents[comp.find(static_cast<std::uint32_t>(p))];
            e.x0 = std::min(e.x0, x), e.y0 = std::min(e.y0, y), e.x1 = std::max(e.x1, x), e.y1 = std::max(e.y1, y);
        }
    for (int block = std::max(1, s.blockSize);; block *= 2) {
        // Key: component, and the block within it when the component spans more than one block.
        std::map<std::pair<std::uint32_t, std::uint64_t>, std::size_t> index;
        std::vector<DetectedLight> lights;
        std::vector<std::array<double, 2>> moments;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const std::size_t p = static_cast<std::size_t>(y) * W + x;
                if (!bright[p]) continue;
                const std::uint32_t c = comp.find(static_cast<std::uint32_t>(p));
                const Extent& e = extents[c];
                const bool split = e.x1 - e.x0 >= block || e.y1 - e.y0 >= block;
                const std::uint64_t cell = split ? (static_cast<std::uint64_t>((y - e.y0) / block) << 32) |
                                                       static_cast<std::uint64_t>((x - e.x0) / block)
                                                 : 0;
                auto [it, inserted] = index.try_emplace({c, cell}, lights.size());
                if (inserted) {
                    lights.emplace_back();
                    moments.push_back({0.0, 0.0});
                }
                DetectedLight& l = lights[it->second];
                const double r = std::max(0.0f, plate.value(p, plate.r)), g = std::max(0.0f, plate.value(p, plate.g)),
                             b = std::max(0.0f, plate.value(p, plate.b));
                l.flux[0] += r, l.flux[1] += g, l.flux[2] += b;
                ++l.pixels;
                l.peak = std::max(l.peak, double(lum[p]));
                moments[it->second][0] += lum[p] * (x + 0.5);
                moments[it->second][1] += lum[p] * (y + 0.5);
            }
        if (lights.size() > s.maxLights && block < std::max(W, H)) continue;
        // Centroids in the display window; lights ordered by component then block (deterministic).
        for (std::size_t i = 0; i < lights.size(); ++i) {
            const double w = luminance(lights[i].flux[0], lights[i].flux[1], lights[i].flux[2]);
            lights[i].x = moments[i][0] / w + plate.dataOffsetX();
            lights[i].y = moments[i][1] / w + plate.dataOffsetY();
        }
        std::vector<DetectedLight> sorted;
        for (const auto& [key, i] : index) sorted.push_back(lights[i]);
        rep.lights = std::move(sorted);
        rep.blockSize = block;
        return rep;
    }
}

} // namespace ff::image
