#include "core/error.h"
#include "core/units.h"
#include "ghosts/mesh_clip.h"
#include "ghosts/shaped_ghosts.h"
#include "ghosts/shaped_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>

namespace ff::ghosts {

namespace {

// One light's ghost at the two table angles around its field angle (the four fields around it).
struct Instance {
    std::size_t light;
    MeshInstance mesh;
    Placement placement;
    double flux = 0.0;                   ///< summed over the channels
    std::array<double, 3> channelFlux{}; ///< per channel
};

} // namespace

namespace {

// A gridded instance's mesh is decimated while its cells span at most this many grid cells (the
// bicubic sub-cells place the light within the tolerance inside them) and it keeps this many cells
// per side.
constexpr double kGridCellsPerMeshCell = 2.0;
constexpr int kMinGridCells = 8;
// On the grid, a polygon narrower than this many cells on both axes is splatted bilinearly at its
// vertices' mean: a tent of one cell instead of its exact coverage.
constexpr float kSplatBelowCells = 1.0f;
// Where the bicubic stencil is incomplete, gridded cells cut by an edge get sub-cells of about this
// many grid cells.
constexpr double kGridSubcellCells = 2.0;

} // namespace

double gridErrorSquared(double length, double step) {
    // An edge of unit jump has the spectrum 1 / (2 pi f) across it: beyond the grid's Nyquist
    // frequency 1 / (2 h) it holds 2 Int_{1/2h}^inf df / (4 pi^2 f^2) = h / pi^2 per unit length.
    // The cells' aliases fold about as much back below it: twice that.
    return 2.0 / (std::numbers::pi * std::numbers::pi) * length * step;
}

namespace {

struct Drawn {
    std::vector<std::vector<double>> channel; ///< W frame-sized images
    double energy = 0.0;
    std::size_t triangles = 0;
    /// Triangles per pixel they cover (ShapedPolygons::areaPx), summed over the instances and
    /// channels that drew any, and their number.
    double perPixel = 0.0, mostPerPixel = 0.0; ///< and the largest
    std::size_t drawnSets = 0;

    // What one instance drew at one wavelength.
    void add(double drawnEnergy, std::size_t drawnTriangles, double areaPx) {
        energy += drawnEnergy;
        triangles += drawnTriangles;
        if (!(areaPx > 0.0)) return;
        const double ratio = static_cast<double>(drawnTriangles) / areaPx;
        perPixel += ratio;
        mostPerPixel = std::max(mostPerPixel, ratio);
        ++drawnSets;
    }
};

// The raster's channels into `out`, checked against the frame.
Drawn finishRaster(PolygonRaster& raster, const trace::ImageFrame& frame, std::size_t W, Drawn out) {
    const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
    out.channel = raster.finish();
    if (out.channel.size() != W) throw Error(ErrorKind::Runtime, "the polygon raster drew another frame");
    for (const auto& c : out.channel)
        if (c.size() != pixels) throw Error(ErrorKind::Runtime, "the polygon raster drew another frame");
    return out;
}

// A chunk of instances at a time: their polygons made in parallel, then drawn, on the CPU into
// bands of rows in parallel, each band in the instances' order (the image does not depend on the
// number of threads), or by the raster given (which cuts the meshes itself where it can).
Drawn drawInstances(const ShapedTable& table, const std::vector<ShapedLight>& lights,
                    const std::vector<Instance>& instances, const trace::ImageFrame& frame, std::size_t W,
                    const ShapedRenderSettings& settings, PolygonRaster* raster, float splatBelow = 0.0f) {
    Drawn out;
    const int bands = raster ? 0 : std::clamp(frame.height / 64, 1, 16);
    std::vector<trace::ImageFrame> bandFrames;
    std::vector<int> bandRow;
    for (int b = 0; b < bands; ++b) {
        const int r0 = frame.height * b / bands, r1 = frame.height * (b + 1) / bands;
        trace::ImageFrame f = frame;
        f.height = r1 - r0;
        bandFrames.push_back(f);
        bandRow.push_back(r0);
    }
    std::vector<std::vector<trace::CoverageRaster>> rasters(W);
    for (std::size_t w = 0; w < W; ++w)
        for (const auto& f : bandFrames) rasters[w].emplace_back(f);
    if (raster) {
        // A pixel receives at most the energy of all polygons, which the instances' fluxes bound
        // (the drawn energy follows the interpolated flux within a few per cent).
        double bound = 0.0;
        for (const Instance& in : instances) bound += in.flux;
        raster->begin(frame, W, 2.0 * bound + std::numeric_limits<double>::min());
    }
    if (raster && raster->cutsMeshes(table)) {
        // The raster cuts the meshes itself: the lights and instances are all it is sent.
        std::vector<MeshLight> meshLights(lights.size());
        for (const Instance& in : instances) meshLights[in.light] = {in.placement, lights[in.light].flux};
        std::vector<MeshDraw> draws;
        draws.reserve(instances.size());
        for (const Instance& in : instances) draws.push_back({in.light, in.mesh});
        for (const MeshDrawn& d : raster->drawMeshes(table, meshLights, draws, W, settings, splatBelow))
            out.add(d.energy, d.triangles, d.areaPx);
        return finishRaster(*raster, frame, W, std::move(out));
    }
    constexpr std::size_t kChunk = 4;
    std::vector<ShapedPolygons> polys(kChunk * W);
    for (std::size_t i0 = 0; i0 < instances.size(); i0 += kChunk) {
        const std::size_t i1 = std::min(instances.size(), i0 + kChunk);
        tbb::parallel_for(std::size_t(0), (i1 - i0) * W, [&](std::size_t k) {
            const Instance& in = instances[i0 + k / W];
            polys[k] = {};
            const ShapedLight& light = lights[in.light];
            meshPolygons(table, in.mesh, k % W, in.placement, light.flux[k % W], frame, settings, polys[k]);
        });
        if (raster)
            for (std::size_t k = 0; k < (i1 - i0) * W; ++k) raster->draw(k % W, polys[k]);
        else
            tbb::parallel_for(std::size_t(0), W * bands, [&](std::size_t k) {
                const std::size_t w = k / bands, b = k % bands;
                const float r0 = static_cast<float>(bandRow[b]), r1 = r0 + static_cast<float>(bandFrames[b].height);
                trace::RasterStats unused;
                std::array<glm::dvec2, kMaxPolygon> p{};
                for (std::size_t i = i0; i < i1; ++i) {
                    const ShapedPolygons& ps = polys[(i - i0) * W + w];
                    for (std::size_t qi = 0; qi < ps.polys.size(); ++qi) {
                        const ShapedPolygons::Poly& q = ps.polys[qi];
                        if (q.yMax < r0 - 1.0f || q.yMin > r1 + 1.0f) continue; // a splat reaches a pixel further
                        for (std::uint32_t v = 0; v < q.count; ++v)
                            p[v] = {ps.vertices[q.first + v].x, ps.vertices[q.first + v].y - r0};
                        if (splatBelow > 0.0 && q.yMax - q.yMin < splatBelow) {
                            double x0 = p[0].x, x1 = x0;
                            glm::dvec2 mean(0.0);
                            for (std::uint32_t v = 0; v < q.count; ++v)
                                mean += p[v], x0 = std::min(x0, p[v].x), x1 = std::max(x1, p[v].x);
                            if (x1 - x0 < splatBelow) {
                                rasters[w][b].point(mean / double(q.count), q.energy, unused);
                                continue;
                            }
                        }
                        rasters[w][b].polygon(std::span(p.data(), q.count), q.energy, ps.gradient(qi), unused);
                    }
                }
            });
        for (std::size_t k = 0; k < (i1 - i0) * W; ++k) out.add(polys[k].energy, polys[k].triangles, polys[k].areaPx);
    }
    if (raster) return finishRaster(*raster, frame, W, std::move(out));
    const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
    out.channel.assign(W, std::vector<double>(pixels, 0.0));
    for (std::size_t w = 0; w < W; ++w)
        for (int b = 0; b < bands; ++b) {
            const std::vector<double> band = std::move(rasters[w][b]).release();
            std::copy(band.begin(), band.end(),
                      out.channel[w].begin() + static_cast<std::ptrdiff_t>(bandRow[b]) * frame.width);
        }
    return out;
}

} // namespace

std::vector<MeshDrawn> PolygonRaster::drawMeshes(const ShapedTable&, const std::vector<MeshLight>&,
                                                 const std::vector<MeshDraw>&, std::size_t, const ShapedRenderSettings&,
                                                 float) {
    throw Error(ErrorKind::Runtime, "this polygon raster does not cut meshes");
}

std::vector<char> chooseGridded(const std::vector<std::array<double, 3>>& error2, const std::array<double, 3>& budget,
                                std::array<double, 3>& spent) {
    std::vector<std::pair<double, std::size_t>> order;
    for (std::size_t i = 0; i < error2.size(); ++i) {
        double share = 0.0;
        for (std::size_t c = 0; c < 3; ++c)
            if (error2[i][c] > 0.0)
                share = std::max(share,
                                 budget[c] > 0.0 ? error2[i][c] / budget[c] : std::numeric_limits<double>::infinity());
        order.push_back({share, i});
    }
    std::sort(order.begin(), order.end());
    spent = {};
    std::vector<char> onGrid(error2.size(), 0);
    for (const auto& [share, i] : order) {
        bool fits = std::isfinite(share);
        for (std::size_t c = 0; c < 3 && fits; ++c) fits = error2[i][c] == 0.0 || spent[c] + error2[i][c] <= budget[c];
        if (!fits) break;
        for (std::size_t c = 0; c < 3; ++c) spent[c] += error2[i][c];
        onGrid[i] = 1;
    }
    return onGrid;
}

namespace {

// Where a light falls in the table: between which fields, and how the table's ghosts are placed.
struct TablePosition {
    MeshInstance mesh;
    Placement placement;
};

// Between fields i0 and i0 + 1 of `count` uniform over 0..extent: (i0, fraction), clamped.
std::pair<int, double> bracket(double value, double extent, int count) {
    const double x = count > 1 && extent > 0.0 ? std::clamp(value, 0.0, extent) / extent * (count - 1) : 0.0;
    const int i0 = std::clamp(static_cast<int>(std::floor(x)), 0, std::max(0, count - 2));
    return {i0, count > 1 ? std::clamp(x - i0, 0.0, 1.0) : 0.0};
}

TablePosition positionOf(const ShapedTable& table, const trace::Field& field) {
    TablePosition p;
    if (!table.twoDimensional()) {
        const int A = table.angles();
        const double deg = std::clamp(radToDeg(field.angleRad), 0.0, table.maxAngleDeg);
        const double x = A > 1 ? deg / table.angleStep() : 0.0;
        p.mesh.a0 = std::clamp(static_cast<int>(std::floor(x)), 0, std::max(0, A - 2));
        p.mesh.t = A > 1 ? std::clamp(x - p.mesh.a0, 0.0, 1.0) : 0.0;
        p.placement.azimuthRad = field.azimuthRad;
        return p;
    }
    // The field's tangents (ShapedTable::FieldGrid), mirrored into the table's quadrant.
    const double tan = std::tan(field.angleRad);
    const double tx = -tan * std::sin(field.azimuthRad), ty = tan * std::cos(field.azimuthRad);
    p.placement.mirrorX = tx < 0.0 ? -1.0 : 1.0;
    p.placement.mirrorY = ty < 0.0 ? -1.0 : 1.0;
    std::tie(p.mesh.a0, p.mesh.t) = bracket(std::abs(tx), table.fieldGrid.maxTanX, table.fieldGrid.x);
    std::tie(p.mesh.b0, p.mesh.s) = bracket(std::abs(ty), table.fieldGrid.maxTanY, table.fieldGrid.y);
    return p;
}

// A ghost's flux at a table position and wavelength, interpolated linearly between its fields.
double fluxAt(const ShapedTable& table, const ShapedGhost& g, std::size_t w, const MeshInstance& in) {
    const auto& m = g.meshes[w];
    if (!table.twoDimensional()) {
        const int A = table.angles();
        return (1.0 - in.t) * m[in.a0].flux + in.t * m[std::min(in.a0 + 1, A - 1)].flux;
    }
    // Relative to each field's direct flux: the flux times it, over its interpolation.
    const int X = table.fieldGrid.x, Y = table.fieldGrid.y;
    double weighted = 0.0, directs = 0.0, plain = 0.0;
    for (int k = 0; k < 4; ++k) {
        const std::size_t f =
            static_cast<std::size_t>(std::min(in.b0 + k / 2, Y - 1)) * X + std::min(in.a0 + k % 2, X - 1);
        const double b = (k / 2 ? in.s : 1.0 - in.s) * (k % 2 ? in.t : 1.0 - in.t);
        const double d = w < table.directFlux.size() ? table.directFlux[w][f] : 0.0;
        weighted += b * d * m[f].flux;
        directs += b * d;
        plain += b * m[f].flux;
    }
    return directs > 0.0 ? weighted / directs : plain;
}

// Per light: the interpolation between table angles and its ghosts kept after culling (the culled
// counted in out).
std::vector<Instance> keptInstances(const ShapedTable& table, const std::vector<ShapedLight>& lights,
                                    const ShapedRenderSettings& settings, ShapedRender& out) {
    std::vector<Instance> instances;
    const std::size_t W = std::min<std::size_t>(3, table.wavelengthsNm.size()), G = table.ghosts.size();
    for (std::size_t l = 0; l < lights.size(); ++l) {
        const TablePosition at = positionOf(table, lights[l].field);
        std::vector<std::pair<double, std::size_t>> flux;
        std::vector<std::array<double, 3>> perChannel(G);
        double total = 0.0;
        for (std::size_t g = 0; g < G; ++g) {
            double f = 0.0;
            for (std::size_t w = 0; w < W; ++w) {
                perChannel[g][w] = lights[l].flux[w] * fluxAt(table, table.ghosts[g], w, at.mesh);
                f += perChannel[g][w];
            }
            flux.push_back({f, g});
            total += f;
        }
        std::sort(flux.begin(), flux.end());
        double dropped = 0.0;
        for (const auto& [f, g] : flux) {
            if (f <= 0.0) continue;
            if (dropped + f <= settings.cullShare * total) {
                dropped += f;
                ++out.culled;
                continue;
            }
            Instance in{l, at.mesh, at.placement, f};
            in.mesh.ghost = g;
            in.mesh.irradianceError = settings.irradianceError;
            in.channelFlux = perChannel[g];
            instances.push_back(in);
        }
        if (total > 0.0) out.culledShare = std::max(out.culledShare, dropped / total);
    }
    return instances;
}

// What the split and the tolerances need of each instance (renderShaped).
struct Estimates {
    std::vector<double> irradiance; ///< mean over its mesh, flux per pixel (middle channel)
    std::vector<std::array<double, 3>> norm2, jump2, perimeterPx;
};

Estimates estimateInstances(const ShapedTable& table, const std::vector<Instance>& instances,
                            const trace::ImageFrame& frame, std::size_t W, const ShapedRenderSettings& settings) {
    // Per instance and channel, from its mesh at the lower table angle: the cells' irradiance I
    // (flux per pixel, a cell carrying light where a corner passes every aperture), its squared norm
    // sum I^2 a (a lower bound of the ghost's: Cauchy-Schwarz within each cell), its jumps sum over
    // the cells' shared sides of (I - I')^2 times the side's length (unlit cells, the mesh's border
    // and cells beyond the Fourier grid, which the grid cuts off, count as I' = 0: a uniform ghost
    // gives I^2 times its perimeter; the norm counts the cells in the frame), and the perimeter of
    // its outline's box. At the middle wavelength, its mean irradiance over the whole mesh sets its
    // drawing tolerance.
    Estimates out;
    out.irradiance.assign(instances.size(), 0.0);
    out.norm2.resize(instances.size());
    out.jump2.resize(instances.size());
    out.perimeterPx.resize(instances.size());
    tbb::parallel_for(std::size_t(0), instances.size() * W, [&](std::size_t k) {
        const std::size_t i = k / W, w = k % W;
        const ShapedGhost& gh = table.ghosts[instances[i].mesh.ghost];
        const MeshInstance& mi = instances[i].mesh;
        const ShapedMesh& m =
            gh.meshes[w][table.twoDimensional() ? static_cast<std::size_t>(mi.b0) * table.fieldGrid.x + mi.a0
                                                : static_cast<std::size_t>(mi.a0)];
        if (m.data.empty()) return;
        const int n = gh.grid;
        const std::size_t stride = gh.stride();
        const double px2 = frame.pitchMm * frame.pitchMm;
        auto at = [&](int x, int y) { return &m.data[(static_cast<std::size_t>(y) * (n + 1) + x) * stride]; };
        // A vertex passes when it carries light inside every stored aperture and within the iris's
        // circumcircle on every crossing of the stop (its blades cut a little more).
        const std::size_t nA = gh.apertureSteps.size();
        const double iris = table.iris.blades >= 3 ? table.iris.circumradius : table.iris.radius;
        auto passes = [&](const float* v) {
            if (!(v[2] > 0.0f)) return false;
            for (std::size_t a = 0; a < nA; ++a)
                if (!(v[3 + a] >= 0.0f)) return false;
            for (std::size_t c = 0; c < gh.stopCrossings; ++c)
                if (!(std::hypot(v[3 + nA + 2 * c], v[4 + nA + 2 * c]) <= iris)) return false;
            return true;
        };
        std::vector<double> I(static_cast<std::size_t>(n) * n, 0.0), cellArea(I.size(), 0.0);
        std::vector<char> inFrame(I.size(), 1);
        // Where the light's cells land (placed as it places them), for the grid's and the frame's extents.
        const Placement& place = instances[i].placement;
        const double cs = std::cos(place.azimuthRad), sn = std::sin(place.azimuthRad);
        const auto& g = settings.grid;
        auto centre = [&](const float* p, const float* q, const float* r, const float* u) {
            const double x = 0.25 * (double(p[0]) + q[0] + r[0] + u[0]), y = 0.25 * (double(p[1]) + q[1] + r[1] + u[1]);
            return frame.sensorToPixel(place.mirrorX * (cs * x - sn * y), place.mirrorY * (sn * x + cs * y));
        };
        double meshArea = 0.0, weights = 0.0;
        double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const float *p = at(x, y), *q = at(x + 1, y), *r = at(x + 1, y + 1), *u = at(x, y + 1);
                const double c = 0.5 * std::abs((r[0] - p[0]) * (u[1] - q[1]) - (r[1] - p[1]) * (u[0] - q[0]));
                if (!std::isfinite(c)) continue;
                meshArea += c;
                if (!(c > 0.0) || !(passes(p) || passes(q) || passes(r) || passes(u))) continue;
                const double weight =
                    0.25 * (std::max(0.0f, p[2]) + std::max(0.0f, q[2]) + std::max(0.0f, r[2]) + std::max(0.0f, u[2]));
                const std::size_t cell = static_cast<std::size_t>(y) * n + x;
                weights += weight;
                if (settings.gridError > 0.0 && g.step > 0 && g.width > 0 && g.height > 0) {
                    const glm::dvec2 c0 = centre(p, q, r, u);
                    inFrame[cell] = c0.x >= 0.0 && c0.y >= 0.0 && c0.x <= frame.width && c0.y <= frame.height;
                    if (c0.x < g.x0 || c0.y < g.y0 || c0.x > g.x0 + double(g.width) * g.step ||
                        c0.y > g.y0 + double(g.height) * g.step)
                        continue;
                }
                I[cell] = weight / (c / px2);
                cellArea[cell] = c / px2;
                for (const float* v : {p, q, r, u})
                    x0 = std::min(x0, double(v[0])), x1 = std::max(x1, double(v[0])), y0 = std::min(y0, double(v[1])),
                    y1 = std::max(y1, double(v[1]));
            }
        if (w == W / 2 && meshArea > 0.0) out.irradiance[i] = instances[i].flux / (meshArea / px2);
        if (!(weights > 0.0)) return;
        const double scale = instances[i].channelFlux[w] / weights; // flux per unit of weight
        double n2 = 0.0, j2 = 0.0;
        auto side = [&](const float* a, const float* b, double fallback) {
            const double len = std::hypot(double(a[0]) - b[0], double(a[1]) - b[1]) / frame.pitchMm;
            return std::isfinite(len) ? len : fallback;
        };
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const std::size_t cell = static_cast<std::size_t>(y) * n + x;
                const double here = scale * I[cell], fallback = std::sqrt(cellArea[cell]);
                if (inFrame[cell]) n2 += here * here * cellArea[cell];
                // Its right and lower sides against the neighbour (or the border); its left and upper
                // sides against the border.
                const double right = x + 1 < n ? scale * I[cell + 1] : 0.0;
                const double below = y + 1 < n ? scale * I[cell + n] : 0.0;
                if (here > 0.0 || right > 0.0)
                    j2 += (here - right) * (here - right) * side(at(x + 1, y), at(x + 1, y + 1), fallback);
                if (here > 0.0 || below > 0.0)
                    j2 += (here - below) * (here - below) * side(at(x, y + 1), at(x + 1, y + 1), fallback);
                if (x == 0 && here > 0.0) j2 += here * here * side(at(0, y), at(0, y + 1), fallback);
                if (y == 0 && here > 0.0) j2 += here * here * side(at(x, 0), at(x + 1, 0), fallback);
            }
        out.norm2[i][w] = n2;
        out.jump2[i][w] = j2;
        out.perimeterPx[i][w] = x1 >= x0 ? 2.0 * (x1 - x0 + y1 - y0) / frame.pitchMm : 0.0;
    });
    return out;
}

} // namespace

ShapedRender renderShaped(const ShapedTable& table, const std::vector<ShapedLight>& lights,
                          const trace::ImageFrame& frame, const ShapedRenderSettings& settings, PolygonRaster* raster) {
    ShapedRender out;
    const std::size_t W = std::min<std::size_t>(3, table.wavelengthsNm.size());

    std::vector<Instance> instances = keptInstances(table, lights, settings, out);
    out.drawn = instances.size();

    const Estimates estimates = estimateInstances(table, instances, frame, W, settings);
    const auto& [irradiance, norm2, jump2, perimeterPx] = estimates;
    // Each instance's tolerances: settings.flatnessPx for the instance of highest mean irradiance,
    // growing in inverse proportion to the irradiance up to settings.maxFlatnessPx: a ghost's share
    // of the image's squared error is its irradiance squared times the area its misplaced edges
    // sweep. Its irradianceError (relative to its own brightest pixel) grows in the same proportion:
    // the same absolute error in the pixels of a dimmer ghost.
    const double top = irradiance.empty() ? 0.0 : *std::max_element(irradiance.begin(), irradiance.end());
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const double dim = irradiance[i] > 0.0 ? top / irradiance[i] : std::numeric_limits<double>::infinity();
        instances[i].mesh.flatnessPx = std::min(settings.maxFlatnessPx, settings.flatnessPx * dim);
        if (settings.flatnessPx > 0.0)
            instances[i].mesh.irradianceError *= instances[i].mesh.flatnessPx / settings.flatnessPx;
    }

    // The split. Per channel c, instance i has ||g||^2 >= norm2 and, on the grid, the squared error
    // e^2 = gridErrorSquared(1, h) x jump2 (the edges' spectrum beyond the grid's Nyquist frequency,
    // each side weighted by its jump squared). Taken in increasing order of their largest share of
    // a channel's budget, instances go onto the grid while every channel keeps
    // sum e^2 <= gridError^2 sum ||g||^2 (errors of different ghosts added as uncorrelated).
    std::vector<Instance> direct, gridded;
    const auto& grid = settings.grid;
    if (settings.gridError > 0.0 && grid.step > 0 && grid.width > 0 && grid.height > 0) {
        std::array<double, 3> budget{};
        std::vector<std::array<double, 3>> err(instances.size());
        for (std::size_t i = 0; i < instances.size(); ++i)
            for (std::size_t c = 0; c < W; ++c) {
                budget[c] += norm2[i][c];
                err[i][c] = jump2[i][c] * gridErrorSquared(1.0, grid.step);
            }
        for (double& b : budget) b *= settings.gridError * settings.gridError;
        std::array<double, 3> spent{};
        const std::vector<char> onGrid = chooseGridded(err, budget, spent);
        for (std::size_t c = 0; c < W; ++c)
            if (budget[c] > 0.0)
                out.gridErrorEstimate =
                    std::max(out.gridErrorEstimate, std::sqrt(spent[c] / budget[c]) * settings.gridError);
        for (std::size_t i = 0; i < instances.size(); ++i) {
            if (!onGrid[i]) {
                direct.push_back(instances[i]);
                continue;
            }
            // On the grid: a tolerance in grid cells, the mesh decimated while its cells (a quarter
            // of the outline's box perimeter over the grid) span at most kGridCellsPerMeshCell.
            Instance in = instances[i];
            const ShapedGhost& gh = table.ghosts[in.mesh.ghost];
            const double cellPx = 0.25 * *std::max_element(perimeterPx[i].begin(), perimeterPx[i].end()) / gh.grid;
            // Where an aperture cuts a cell, its chord keeps the direct tolerance (in cells): a
            // coarser chord of a convex outline cuts off flux (about 4/3 sag / radius of it).
            in.mesh.edgeFlatnessPx = in.mesh.flatnessPx / grid.step;
            in.mesh.flatnessPx = settings.gridFlatness;
            in.mesh.irradianceError = std::numeric_limits<double>::infinity();
            in.mesh.decimation = 1;
            for (int d = 2; gh.grid / d >= kMinGridCells; ++d)
                if (gh.grid % d == 0 && d * cellPx <= kGridCellsPerMeshCell * grid.step) in.mesh.decimation = d;
            gridded.push_back(in);
        }
    } else {
        direct = std::move(instances);
    }
    out.gridded = gridded.size();

    Drawn drawn = drawInstances(table, lights, direct, frame, W, settings, raster);
    double energy = drawn.energy;
    out.triangles = drawn.triangles;
    out.trianglesPerPixel = drawn.drawnSets ? drawn.perPixel / static_cast<double>(drawn.drawnSets) : 0.0;
    out.mostTrianglesPerPixel = drawn.mostPerPixel;
    const std::size_t pixels = static_cast<std::size_t>(frame.width) * frame.height;
    for (std::size_t w = 0; w < 3; ++w) {
        out.channel[w] = w < W ? std::move(drawn.channel[w]) : std::vector<double>(pixels, 0.0);
        for (double v : out.channel[w]) out.deposited += v;
    }
    if (!gridded.empty()) {
        // The grid as a frame of its own: cells of step pixels, placed on the frame's pixels.
        trace::ImageFrame gf{grid.width, grid.height, frame.pitchMm * grid.step};
        const glm::dvec2 centre =
            frame.pixelToSensor(grid.x0 + 0.5 * grid.width * grid.step, grid.y0 + 0.5 * grid.height * grid.step);
        gf.centreXMm = centre.x;
        gf.centreYMm = centre.y;
        ShapedRenderSettings onCells = settings;
        onCells.subcellPx = kGridSubcellCells;
        // Uniform elements on the grid: its cells take each element's flux whole, and the hybrid's
        // estimate and its measured frames (docs/performance.md) hold for them; linear ones cost the
        // raster about 1.4 times as much for what the grid's series smooths away.
        onCells.linearDensity = false;
        // On the raster where it cuts the meshes itself (it splats as the CPU's bands do).
        PolygonRaster* gridRaster = raster && raster->cutsMeshes(table) ? raster : nullptr;
        Drawn onGrid = drawInstances(table, lights, gridded, gf, W, onCells, gridRaster, kSplatBelowCells);
        energy += onGrid.energy;
        out.gridTriangles = onGrid.triangles;
        out.gridTrianglesPerCell = onGrid.drawnSets ? onGrid.perPixel / static_cast<double>(onGrid.drawnSets) : 0.0;
        for (std::size_t w = 0; w < 3; ++w) {
            out.grid[w] = w < W ? std::move(onGrid.channel[w])
                                : std::vector<double>(static_cast<std::size_t>(grid.width) * grid.height, 0.0);
            // What the grid holds inside the frame reaches it (the series keeps each cell's flux).
            for (int j = 0; j < grid.height; ++j)
                for (int i = 0; i < grid.width; ++i) {
                    const double x0 = grid.x0 + i * grid.step, y0 = grid.y0 + j * grid.step;
                    const double cx = std::clamp(std::min(x0 + grid.step, double(frame.width)) - std::max(x0, 0.0), 0.0,
                                                 double(grid.step)),
                                 cy = std::clamp(std::min(y0 + grid.step, double(frame.height)) - std::max(y0, 0.0),
                                                 0.0, double(grid.step));
                    out.deposited += out.grid[w][static_cast<std::size_t>(j) * grid.width + i] * cx * cy /
                                     (double(grid.step) * grid.step);
                }
        }
    }
    out.offImage = std::max(0.0, energy - out.deposited);
    return out;
}

} // namespace ff::ghosts
