#include "ghosts/ghost_table.h"

#include "core/error.h"
#include "core/units.h"
#include "ghosts/shaped_ghosts.h"
#include "ghosts/shaped_mesh.h"
#include "optics/paraxial.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>

namespace ff::ghosts {

TableSettings TableSettings::named(int grid, int angles, const std::string& sensor, const std::string& coating,
                                   double maxAngleDeg) {
    auto require = [](bool ok, const std::string& what) {
        if (!ok) throw Error(ErrorKind::Usage, what);
    };
    require(grid >= 4 && grid <= 512,
            "the table's grid (table_grid, --table-grid) must be 4..512 cells per side, got " + std::to_string(grid));
    require(angles >= 2 && angles <= 1024,
            "the table's field angles (table_angles, --table-angles) must be 2..1024, got " + std::to_string(angles));
    require(maxAngleDeg >= 0.0 && maxAngleDeg <= 85.0,
            "the table's largest field angle (max_angle, --max-angle) must be 0..85 degrees");
    TableSettings s;
    s.grid = grid;
    s.angles = angles;
    s.sensor = trace::sensorPlaneNamed(sensor);
    s.coating = trace::coatingNamed(coating);
    s.maxAngleDeg = maxAngleDeg;
    return s;
}

std::pair<std::size_t, double> locate(const std::vector<double>& angles, double a) {
    if (angles.size() < 2 || a <= angles.front()) return {0, 0.0};
    if (a >= angles.back()) return {angles.size() - 2, 1.0};
    const auto it = std::upper_bound(angles.begin(), angles.end(), a);
    const std::size_t i = static_cast<std::size_t>(it - angles.begin()) - 1;
    return {i, (a - angles[i]) / (angles[i + 1] - angles[i])};
}

namespace {

double lerp(double a, double b, double t) {
    return a + (b - a) * t;
}

ProfileFit lerp(const ProfileFit& a, const ProfileFit& b, double t) {
    return {lerp(a.widthR, b.widthR, t), lerp(a.widthT, b.widthT, t), lerp(a.peak, b.peak, t),
            lerp(a.error, b.error, t)};
}

} // namespace

TableEntry interpolate(const TableEntry& a, const TableEntry& b, double t) {
    // Where the ghost is dark at one end of the interval (it is switched on or off within it), its
    // shape is the lit end's and only its light fades: interpolating its centroid and widths towards
    // those of no light would shrink it onto the axis.
    if ((a.flux <= 0.0) != (b.flux <= 0.0)) {
        const bool fromB = a.flux <= 0.0;
        TableEntry e = fromB ? b : a;
        const double fade = fromB ? t : 1.0 - t;
        e.flux *= fade;
        e.gaussian.peak *= fade;
        e.cos2.peak *= fade;
        e.surviving = lerp(a.surviving, b.surviving, t);
        return e;
    }
    TableEntry e;
    e.centroidY = lerp(a.centroidY, b.centroidY, t);
    e.sigmaR = lerp(a.sigmaR, b.sigmaR, t);
    e.sigmaT = lerp(a.sigmaT, b.sigmaT, t);
    e.flux = lerp(a.flux, b.flux, t);
    e.surviving = lerp(a.surviving, b.surviving, t);
    e.gaussian = lerp(a.gaussian, b.gaussian, t);
    e.cos2 = lerp(a.cos2, b.cos2, t);
    return e;
}

TableEntry GhostTable::at(std::size_t ghost, std::size_t w, double a) const {
    const TableGhost& g = ghosts[ghost];
    const auto [i, t] = locate(g.anglesDeg, a);
    const auto& row = g.entries[w];
    return g.anglesDeg.size() < 2 ? row[0] : interpolate(row[i], row[i + 1], t);
}

double GhostTable::directAt(std::size_t w, double a) const {
    const auto [i, t] = locate(anglesDeg, a);
    return anglesDeg.size() < 2 ? directY[w][0] : directY[w][i] + (directY[w][i + 1] - directY[w][i]) * t;
}

double GhostTable::magnification(std::size_t ghost, std::size_t w, double a) const {
    // On the axis both heights vanish: use the ghost's first non-zero angle.
    const std::vector<double>& own = ghosts[ghost].anglesDeg;
    const double angle = (own.size() > 1 && a < own[1]) ? std::max(a, own[1]) : a;
    const double d = directAt(w, angle);
    return d != 0.0 ? at(ghost, w, angle).centroidY / d : 0.0;
}

std::size_t GhostTable::nearestWavelength(double lambda) const {
    std::size_t best = 0;
    for (std::size_t w = 1; w < wavelengthsNm.size(); ++w)
        if (std::abs(wavelengthsNm[w] - lambda) < std::abs(wavelengthsNm[best] - lambda)) best = w;
    return best;
}

std::array<std::size_t, 3> GhostTable::rgbChannels() const {
    return {nearestWavelength(650.0), nearestWavelength(550.0), nearestWavelength(450.0)};
}

std::size_t GhostTable::entryCount() const {
    std::size_t n = 0;
    for (const TableGhost& g : ghosts) n += g.anglesDeg.size();
    return n;
}

namespace {

// One ghost's entry at table angle a and wavelength w: its mesh cut into polygons at azimuth 0,
// first flat (its flux, exactly as drawn without subdivision, and its spreads), then subdivided to a
// tenth of a pixel of the image it is fitted to (FitOptions: the larger spread over an eighth of its
// pixels), which sets the moments and the profiles.
TableEntry fitEntry(const ShapedTable& table, std::size_t g, std::size_t w, int a, const FitOptions& options) {
    const ShapedGhost& gh = table.ghosts[g];
    const ShapedMesh& mesh = gh.meshes[w][static_cast<std::size_t>(a)];
    TableEntry e;
    if (mesh.data.empty() || !(mesh.flux > 0.0)) return e;
    // Pass 1: a frame of 1 um pixels on the axis; no subdivision.
    // Uniform elements: the fits' moments are those of the flat cells.
    ShapedRenderSettings flat;
    flat.linearDensity = false;
    flat.subcellPx = std::numeric_limits<double>::infinity();
    const trace::ImageFrame micron{0, 0, 1e-3};
    ShapedPolygons coarse;
    meshPolygons(table, {g, a, 0.0, std::numeric_limits<double>::infinity()}, w, {}, 1.0, micron, flat, coarse);
    const PolygonMoments m = polygonMoments(coarse, micron, options.maxRadiusMm);
    if (!(m.energy > 0.0)) return e;
    // Pass 2: pixels of the fit's image, centred on the ghost.
    const double spread = std::max({std::sqrt(m.mxx), std::sqrt(m.myy), 1e-3});
    const trace::ImageFrame local{options.imageSize, options.imageSize,
                                  2.0 * options.extentSigmas * spread / options.imageSize, m.centroidX, m.centroidY};
    ShapedRenderSettings fine = flat;
    fine.subcellPx = 1.0;
    ShapedPolygons polys;
    meshPolygons(table, {g, a, 0.0, 0.1}, w, {}, 1.0, local, fine, polys);
    const GhostFit f = fitGhost(polys, local, options);
    e.centroidY = f.centroidY;
    e.sigmaR = f.sigmaR;
    e.sigmaT = f.sigmaT;
    e.gaussian = f.gaussian;
    e.cos2 = f.cos2;
    // The flux is the flat cells' (the mesh's own, as drawn without subdivision); the profiles carry it.
    e.flux = m.energy;
    if (f.flux > 0.0) {
        e.gaussian.peak *= m.energy / f.flux;
        e.cos2.peak *= m.energy / f.flux;
    }
    const double cell = (gh.pupilX1 - gh.pupilX0) * (gh.pupilY1 - gh.pupilY0) / (double(gh.grid) * gh.grid);
    const double pupil = std::numbers::pi * table.pupilRadiusMm * table.pupilRadiusMm;
    e.surviving = pupil > 0.0 ? std::min(1.0, polys.pupilCells * cell / pupil) : 0.0;
    return e;
}

} // namespace

GhostTable fitShapedTable(const ShapedTable& table, const optics::Lens& lens, const Progress& progress) {
    GhostTable t;
    t.lensName = table.lensName;
    t.lensFile = lens.file;
    t.lensHash = table.lensHash;
    t.efl = optics::paraxialEfl(lens, lines::d);
    t.sensorZ = table.sensorZ;
    t.sensorSizeMm = table.sensorSizeMm;
    t.apertureBlades = lens.apertureBlades;
    t.bladeRotationDeg = lens.bladeRotationDeg;
    t.wavelengthsNm = table.wavelengthsNm;
    // The fits describe a ghost by its radial and tangential widths about the line to the light: a
    // two-dimensional table's ghosts have none of that symmetry, and no fits.
    if (table.twoDimensional()) return t;
    const int A = table.angles();
    for (int a = 0; a < A; ++a) t.anglesDeg.push_back(table.angleStep() * a);
    t.directY = table.directY;
    const std::size_t W = table.wavelengthsNm.size(), G = table.ghosts.size();
    FitOptions options;
    options.maxRadiusMm = std::hypot(table.sensorSizeMm.first, table.sensorSizeMm.second);
    t.ghosts.resize(G);
    for (std::size_t g = 0; g < G; ++g) {
        t.ghosts[g].pair = table.ghosts[g].pair;
        t.ghosts[g].anglesDeg = t.anglesDeg;
        t.ghosts[g].entries.assign(W, std::vector<TableEntry>(static_cast<std::size_t>(A)));
    }
    const std::size_t total = G * W * static_cast<std::size_t>(A);
    std::atomic<std::size_t> done = 0;
    std::mutex mutex;
    tbb::parallel_for(std::size_t(0), total, [&](std::size_t k) {
        const std::size_t g = k / (W * A), w = (k / A) % W;
        const int a = static_cast<int>(k % A);
        t.ghosts[g].entries[w][static_cast<std::size_t>(a)] = fitEntry(table, g, w, a, options);
        if (progress) {
            const std::size_t d = ++done;
            std::lock_guard<std::mutex> lock(mutex);
            progress(d, total);
        }
    });
    return t;
}

ShapedTable buildShapedTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress) {
    const auto start = std::chrono::steady_clock::now();
    ShapedTable t = traceShapedTable(lens, settings, progress);
    const std::size_t G = t.ghosts.size();
    Progress fits;
    if (progress)
        fits = [&](std::size_t done, std::size_t total) {
            progress(G + G * done / std::max<std::size_t>(total, 1), 2 * G);
        };
    t.fitted = fitShapedTable(t, lens, fits);
    t.fitted.settingsKey = shapedCacheKey(lens, settings);
    t.buildSeconds = t.fitted.buildSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return t;
}

GhostTable buildGhostTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress) {
    return buildShapedTable(lens, settings, progress).fitted;
}

} // namespace ff::ghosts
