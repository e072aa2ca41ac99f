#include "trace/traced_flare.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/bundle_moments.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace ff::trace {

std::array<double, 3> cie1931(double l) {
    // Wyman, Sloan & Shirley 2013, multi-lobe piecewise Gaussian fit (their equation 2).
    auto g = [l](double mu, double s1, double s2) {
        const double t = (l - mu) / (l < mu ? s1 : s2);
        return std::exp(-0.5 * t * t);
    };
    const double x = 1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2);
    const double y = 0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1);
    const double z = 1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8);
    return {x, y, z};
}

void colourWeights(int n, std::vector<double>& lambdas, std::vector<std::array<double, 3>>& weights) {
    lambdas.clear();
    weights.clear();
    if (n == 0) {
        lambdas = {650.0, 550.0, 450.0};
        weights = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
        return;
    }
    std::array<double, 3> white{};
    for (int i = 0; i < n; ++i) {
        const double l = 400.0 + 300.0 * (i + 0.5) / n;
        const auto [X, Y, Z] = cie1931(l);
        // XYZ -> linear sRGB (IEC 61966-2-1).
        const std::array<double, 3> rgb = {3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
                                           0.0557 * X - 0.2040 * Y + 1.0570 * Z};
        lambdas.push_back(l);
        weights.push_back(rgb);
        for (int c = 0; c < 3; ++c) white[c] += rgb[c];
    }
    for (auto& w : weights)
        for (int c = 0; c < 3; ++c) w[c] /= white[c];
}

namespace {

constexpr int kEdgeRefinement = 4; // sub-grid per side for cells on a vignetting edge

// Re-traces every flagged cell on a kEdgeRefinement^2 sub-grid (all cells in one batch) and draws
// the sub-cells with the usual rules.
void refineEdgeCells(const EmbreeTracer& tracer, const LensAtWavelength& L, const std::vector<PathStep>& steps,
                     const PupilFrame& pupil, const Field& field, const Bundle& centres, const std::vector<RayResult>& centreHits,
                     const std::vector<char>& edge,
                     double scale, const ImageFrame& frame, std::vector<double>& image, RasterStats& stats) {
    std::vector<Bundle> subC, subK;
    std::vector<std::optional<std::pair<glm::dvec2, glm::dvec2>>> parentJacobian;
    for (int j = 0; j < centres.n; ++j)
        for (int i = 0; i < centres.n; ++i) {
            if (!edge[static_cast<std::size_t>(j) * centres.n + i]) continue;
            glm::dvec2 du, dv;
            if (cellJacobian(centres, centreHits, frame, i, j, du, dv)) parentJacobian.emplace_back(std::make_pair(du / double(kEdgeRefinement), dv / double(kEdgeRefinement)));
            else parentJacobian.emplace_back(std::nullopt);
            const double cx = centres.x0 + (i + 0.5) * centres.cell, cy = centres.y0 + (j + 0.5) * centres.cell;
            subC.push_back(gridBundle(pupil, field, kEdgeRefinement, cx, cy, 0.5 * centres.cell, false));
            subK.push_back(cornerBundle(pupil, field, subC.back()));
        }
    if (subC.empty()) return;
    std::vector<optics::Ray> rays;
    for (std::size_t s = 0; s < subC.size(); ++s) {
        rays.insert(rays.end(), subC[s].rays.begin(), subC[s].rays.end());
        rays.insert(rays.end(), subK[s].rays.begin(), subK[s].rays.end());
    }
    std::vector<RayResult> hits(rays.size());
    tracer.trace(L, steps, rays, hits);
    std::size_t offset = 0;
    for (std::size_t s = 0; s < subC.size(); ++s) {
        const std::vector<RayResult> c(hits.begin() + static_cast<long>(offset), hits.begin() + static_cast<long>(offset + subC[s].rays.size()));
        offset += subC[s].rays.size();
        const std::vector<RayResult> k(hits.begin() + static_cast<long>(offset), hits.begin() + static_cast<long>(offset + subK[s].rays.size()));
        offset += subK[s].rays.size();
        rasterizeCells(subC[s], c, k, scale, frame, image, stats, {}, parentJacobian[s] ? &*parentJacobian[s] : nullptr);
    }
}

} // namespace

TracedFlare renderTracedFlare(const optics::Lens& lensIn, const TracedFlareOptions& o) {
    const optics::Lens lens = withCoating(lensIn, o.coating);
    const double sensorZ = sensorPlaneZ(lens, o.sensor);
    TracedFlare out;
    out.width = o.frame.width;
    out.height = o.frame.height;
    std::vector<std::array<double, 3>> weights;
    colourWeights(o.spectralSamples, out.wavelengthsNm, weights);
    const PupilFrame pupil = pupilFrame(lens);
    const auto ghosts = enumerateGhosts(lens);
    out.ghostCount = ghosts.size();
    const LensAtWavelength geometry(lens, lines::d, sensorZ);
    const EmbreeTracer tracer(geometry);
    const std::size_t pixels = static_cast<std::size_t>(o.frame.width) * o.frame.height;

    // One flux image per wavelength, rendered in parallel; each is filled in a fixed order, so the
    // result does not depend on the number of threads.
    // Each path's pupil region, found once for all wavelengths: over the regions at the shortest and
    // the longest.
    const auto [shortest, longest] = std::minmax_element(out.wavelengthsNm.begin(), out.wavelengthsNm.end());
    const LensAtWavelength ends[] = {LensAtWavelength(lens, *shortest, sensorZ), LensAtWavelength(lens, *longest, sensorZ)};
    std::vector<std::vector<PathStep>> ghostSteps;
    std::vector<PupilRegion> regions;
    const auto directSteps = pathSteps(lens, std::nullopt);
    const PupilRegion directRegion = bandRegion(pupil, o.field, o.sampling, ends, directSteps);
    for (const GhostPair& g : ghosts) {
        ghostSteps.push_back(pathSteps(lens, g));
        regions.push_back(bandRegion(pupil, o.field, o.sampling, ends, ghostSteps.back()));
    }

    std::vector<std::vector<double>> layers(out.wavelengthsNm.size());
    out.stats.resize(out.wavelengthsNm.size());
    tbb::parallel_for(std::size_t(0), out.wavelengthsNm.size(), [&](std::size_t w) {
        const LensAtWavelength L(lens, out.wavelengthsNm[w], sensorZ);
        layers[w].assign(pixels, 0.0);
        // The direct image's energy normalises the flux.
        const Bundle direct = regionBundle(pupil, o.field, directRegion, o.grid);
        std::vector<RayResult> hits(direct.rays.size());
        tracer.trace(L, directSteps, direct.rays, hits);
        const double directEnergy = measureBundle(direct, hits).energy;
        if (directEnergy <= 0.0) return; // the source is fully vignetted: no flare
        for (std::size_t gi = 0; gi < ghosts.size(); ++gi) {
            const auto& steps = ghostSteps[gi];
            const Bundle centres = regionBundle(pupil, o.field, regions[gi], o.grid);
            const Bundle corners = cornerBundle(pupil, o.field, centres);
            std::vector<RayResult> c(centres.rays.size()), k(corners.rays.size());
            tracer.trace(L, steps, centres.rays, c);
            tracer.trace(L, steps, corners.rays, k);
            const std::vector<char> edge = edgeCells(centres, c, k);
            rasterizeCells(centres, c, k, 1.0 / directEnergy, o.frame, layers[w], out.stats[w], edge);
            refineEdgeCells(tracer, L, steps, pupil, o.field, centres, c, edge, 1.0 / directEnergy, o.frame, layers[w], out.stats[w]);
        }
    });

    out.rgb.assign(pixels * 3, 0.0f);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int ch = 0; ch < 3; ++ch) {
            double v = 0.0;
            for (std::size_t w = 0; w < layers.size(); ++w) v += weights[w][ch] * layers[w][p];
            out.rgb[p * 3 + ch] = static_cast<float>(std::max(0.0, v));
        }
    return out;
}

Field fieldForSensorPoint(const optics::Lens& lens, double sensorZ, double xMm, double yMm) {
    const double r = std::sqrt(xMm * xMm + yMm * yMm);
    Field f;
    f.azimuthRad = std::atan2(-xMm, yMm); // image at r (-sin az, cos az)
    if (r == 0.0) return f;
    const LensAtWavelength L(lens, lines::d, sensorZ);
    const PupilFrame pupil = pupilFrame(lens);
    const auto steps = pathSteps(lens, std::nullopt);
    // Height of the chief ray on the sensor for a field angle (azimuth 0: image along +y).
    auto height = [&](double theta) -> std::optional<double> {
        const Bundle one = gridBundle(pupil, {theta, 0.0}, 1, 0.0, 0.0, 1e-9, false);
        const SequentialResult s = traceSequential(L, steps, one.rays[0]);
        if (s.status != optics::RayStatus::Ok) return std::nullopt;
        return s.ray.origin.y;
    };
    // Bisection on the angle; the image height grows monotonically with it for a photographic lens.
    double lo = 0.0, hi = degToRad(89.0);
    for (int it = 0; it < 100 && hi - lo > 1e-13; ++it) {
        const double mid = 0.5 * (lo + hi);
        const auto h = height(mid);
        if (h && *h < r) lo = mid;
        else hi = mid;
    }
    const auto reached = height(lo);
    if (!reached || std::abs(*reached - r) > 1e-6 * (1.0 + r))
        throw Error(ErrorKind::Input, "no field angle images a source at " + text::fixed(r, 3) +
                                          " mm from the axis (the chief ray does not reach it); is the light outside the lens's field?");
    f.angleRad = lo;
    return f;
}

} // namespace ff::trace
