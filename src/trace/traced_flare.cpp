#include "trace/traced_flare.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/adaptive_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

namespace ff::trace {

namespace {

// Ghosts whose flux (summed over the wavelengths) is under cullFraction of the strongest's: marked 1,
// their count and share of the ghost flux in out.
std::vector<char> cullFaint(const std::vector<double>& ghostFlux, double cullFraction, TracedFlare& out) {
    const double strongest = ghostFlux.empty() ? 0.0 : *std::max_element(ghostFlux.begin(), ghostFlux.end());
    const double total = std::accumulate(ghostFlux.begin(), ghostFlux.end(), 0.0);
    std::vector<char> culled(ghostFlux.size(), 0);
    double culledFlux = 0.0;
    for (std::size_t g = 0; g < ghostFlux.size(); ++g)
        if (ghostFlux[g] < cullFraction * strongest) {
            culled[g] = 1;
            ++out.culled;
            culledFlux += ghostFlux[g];
        }
    out.culledShare = total > 0.0 ? culledFlux / total : 0.0;
    return culled;
}

// The wavelengths' images weighted into linear RGB (R, G, B interleaved), negatives clipped.
std::vector<float> combineRgb(std::vector<CoverageRaster> rasters, const std::vector<std::array<double, 3>>& weights,
                              std::size_t pixels) {
    std::vector<std::vector<double>> layers;
    for (CoverageRaster& r : rasters) layers.push_back(std::move(r).release());
    std::vector<float> rgb(pixels * 3, 0.0f);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int ch = 0; ch < 3; ++ch) {
            double v = 0.0;
            for (std::size_t w = 0; w < layers.size(); ++w) v += weights[w][ch] * layers[w][p];
            rgb[p * 3 + ch] = static_cast<float>(std::max(0.0, v));
        }
    return rgb;
}

// The direct path's and every ghost's steps and pupil region, each region found once for all
// wavelengths: over the regions at the shortest and the longest.
struct Paths {
    std::vector<PathStep> directSteps;
    PupilRegion directRegion;
    std::vector<std::vector<PathStep>> ghostSteps;
    std::vector<PupilRegion> regions;
};
Paths pathsOf(const optics::Lens& lens, const std::vector<GhostPair>& ghosts, const PupilFrame& pupil,
              const TracedFlareOptions& o, const std::vector<double>& wavelengthsNm, double sensorZ) {
    const auto [shortest, longest] = std::minmax_element(wavelengthsNm.begin(), wavelengthsNm.end());
    const LensAtWavelength ends[] = {LensAtWavelength(lens, *shortest, sensorZ),
                                     LensAtWavelength(lens, *longest, sensorZ)};
    Paths p;
    p.directSteps = pathSteps(lens, std::nullopt);
    p.directRegion = bandRegion(pupil, o.field, o.sampling, ends, p.directSteps);
    for (const GhostPair& g : ghosts) {
        p.ghostSteps.push_back(pathSteps(lens, g));
        p.regions.push_back(bandRegion(pupil, o.field, o.sampling, ends, p.ghostSteps.back()));
    }
    return p;
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
    const LensAtWavelength geometry(lens, lines::d, sensorZ, LensAtWavelength::Films::Exact);
    const EmbreeTracer tracer(geometry);
    const std::size_t pixels = static_cast<std::size_t>(o.frame.width) * o.frame.height;
    const std::size_t W = out.wavelengthsNm.size(), G = ghosts.size();
    RefineSettings settings = RefineSettings::refined(o.refinement);
    if (!o.adaptive) settings.maxDepth = 0;
    const int n = static_cast<int>(std::lround(o.grid * o.refinement));
    if (n < 2 || n > 4096)
        throw Error(ErrorKind::Usage, "the starting grid x the refinement must be 2 to 4096 cells per side");

    const Paths paths = pathsOf(lens, ghosts, pupil, o, out.wavelengthsNm, sensorZ);
    const std::vector<PathStep>& directSteps = paths.directSteps;
    const PupilRegion& directRegion = paths.directRegion;
    const std::vector<std::vector<PathStep>>& ghostSteps = paths.ghostSteps;
    const std::vector<PupilRegion>& regions = paths.regions;
    std::vector<LensAtWavelength> Ls;
    Ls.reserve(W);
    for (double l : out.wavelengthsNm) Ls.emplace_back(lens, l, sensorZ);

    const glm::dvec3 dir = fieldDirection(o.field, pupil.eflSign);
    const double back = (pupil.z - pupil.startZ) / dir.z; // from the pupil plane back to the start plane
    auto sampler = [&](const LensAtWavelength& L, const std::vector<PathStep>& steps) -> PupilSampler {
        return [&, lp = &L, sp = &steps](std::span<const glm::dvec2> pts, std::span<PupilSample> res) {
            std::vector<optics::Ray> rays(pts.size());
            for (std::size_t i = 0; i < pts.size(); ++i) rays[i] = {glm::dvec3(pts[i], pupil.z) - back * dir, dir};
            std::vector<RayResult> hits(pts.size());
            tracer.trace(*lp, *sp, rays, hits);
            for (std::size_t i = 0; i < pts.size(); ++i)
                res[i] = {o.frame.sensorToPixel(hits[i].sensorPoint.x, hits[i].sensorPoint.y), hits[i].weight,
                          hits[i].status == optics::RayStatus::Ok};
        };
    };
    auto startGrid = [&](const PupilRegion& r, const RefineSettings& s, PupilSampler sm) {
        const Bundle b = regionBundle(pupil, o.field, r, n); // the grid's square and launched cells
        return std::make_unique<AdaptiveGrid>(n, b.x0, b.y0, b.cell, b.launched, s, std::move(sm), r.litPoints);
    };

    // Pass 1, every path on its starting grid: the direct image's energy (its vignetting edges
    // resolved) normalises each wavelength, and the ghosts' energies decide which are culled.
    std::vector<double> directEnergy(W, 0.0);
    std::vector<std::vector<std::unique_ptr<AdaptiveGrid>>> grids(W);
    for (auto& g : grids) g.resize(G);
    tbb::parallel_for(std::size_t(0), W * (G + 1), [&](std::size_t t) {
        const std::size_t w = t / (G + 1), g = t % (G + 1);
        if (g == G) {
            auto direct = startGrid(directRegion, RefineSettings::energyOnly(), sampler(Ls[w], directSteps));
            direct->refine();
            directEnergy[w] = direct->energy();
        } else {
            grids[w][g] = startGrid(regions[g], settings, sampler(Ls[w], ghostSteps[g]));
        }
    });
    std::vector<double> ghostFlux(G, 0.0);
    for (std::size_t w = 0; w < W; ++w)
        if (directEnergy[w] > 0.0)
            for (std::size_t g = 0; g < G; ++g) ghostFlux[g] += grids[w][g]->energy() / directEnergy[w];
    const std::vector<char> culled = cullFaint(ghostFlux, o.cullFraction, out);

    // Pass 2, per wavelength in parallel: the ghosts refined in parallel a few at a time, then drawn
    // in ghost order, so the image does not depend on the number of threads.
    std::vector<CoverageRaster> rasters(W, CoverageRaster(o.frame));
    out.stats.resize(W);
    std::vector<AdaptiveStats> ghostStats(W * G);
    constexpr std::size_t kChunk = 8; // ghosts refined at once per wavelength: bounds the memory held
    tbb::parallel_for(std::size_t(0), W, [&](std::size_t w) {
        if (directEnergy[w] <= 0.0) return; // the source is fully vignetted: no flare
        for (std::size_t g0 = 0; g0 < G; g0 += kChunk) {
            const std::size_t g1 = std::min(G, g0 + kChunk);
            tbb::parallel_for(g0, g1, [&](std::size_t g) {
                if (culled[g])
                    grids[w][g].reset();
                else
                    grids[w][g]->refine(o.frame.width, o.frame.height);
            });
            for (std::size_t g = g0; g < g1; ++g) {
                const std::unique_ptr<AdaptiveGrid> grid = std::move(grids[w][g]);
                if (!grid) continue;
                grid->draw(1.0 / directEnergy[w], rasters[w], out.stats[w]);
                ghostStats[w * G + g] = grid->stats();
            }
        }
    });
    for (const AdaptiveStats& s : ghostStats) {
        out.samples += s.samples;
        out.budgetHits += s.budgetHit;
        out.maxDepth = std::max(out.maxDepth, s.depth);
    }

    out.rgb = combineRgb(std::move(rasters), weights, pixels);
    return out;
}

} // namespace ff::trace
