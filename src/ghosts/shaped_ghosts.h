#pragma once
// Shaped ghosts: every ghost kept as the mesh its rays draw on the sensor, so that the fast path
// shows the iris polygon, sharp rims, vignetting cut-offs and caustics the traced flare shows
// (after Hullin, Eisemann, Seidel & Lee 2011, "Physically-based real-time lens flare rendering").
//
// Model. For each ghost, wavelength and field angle of a uniform set 0..thetaMax (source at azimuth
// 0, its direct image at +y), a square of the entrance-pupil plane covering the ghost's light is
// cut into n x n cells and its (n+1)^2 corner rays are traced with every aperture open
// (traceSequential's open margins). Each vertex keeps where its ray lands (mm), its Fresnel /
// coating weight as flux per cell (relative to the direct image at that wavelength and angle), its
// margin inside each clear aperture that cuts the ghost somewhere (mm, negative outside) and its hit
// points on the stop plane. A cell is two triangles; over a triangle every attribute is taken as
// linear, so each aperture's edge is a straight cut through it and the light that passes is the
// triangle clipped by one half-plane per margin. The iris is clipped blade by blade at render time
// in the frame of the light (a polygon iris does not turn with the light's azimuth), so its corners
// are exact. A clipped triangle carries its mean weight x its lit share of the cell area, spread
// uniformly over its image on the sensor: folds of the map (caustics) brighten by themselves and
// the flux is the integral of the weight over the lit pupil whatever the shape on the sensor.
//
// Between table angles every vertex attribute is interpolated by a cubic (Catmull-Rom) through the
// four nearest angles (the same vertex of the grid, whose square moves smoothly with the angle;
// linearly where a ray is lost at one of them); a light at azimuth phi rotates the landing points
// by phi and the iris by -phi in the table's frame.
//
// An anamorphic lens (no rotational symmetry, but mirror symmetric about the x-z and y-z planes:
// its surfaces are biconics centred on the axis) has a table over a two-dimensional field: a grid of
// directions uniform in their tangents over one quadrant (ShapedTable::FieldGrid), interpolated by
// bicubic Catmull-Rom between the sixteen nearest fields; a light in another quadrant is the mirror
// image of one in this quadrant, its landing points and its iris mirrored (docs/anamorphic.md).

#include "ghosts/instancing.h"
#include "ghosts/polygons.h"
#include "ghosts/table_data.h"
#include "optics/lens.h"
#include "trace/flare_raster.h"
#include "trace/ghost_analysis.h"
#include "trace/pupil_sampling.h"

#include <glm/vec2.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace ff::ghosts {

/// One ghost at one wavelength and field angle.
struct ShapedMesh {
    double flux = 0.0;       ///< relative to the direct image (iris at the table's orientation)
    std::vector<float> data; ///< (n+1)^2 vertices x ShapedGhost::stride(); empty: no light
};

struct ShapedGhost {
    trace::GhostPair pair;
    int grid = 0; ///< cells per side of its pupil meshes
    /// The rectangle of the pupil plane its meshes cover, mm: corners (x0, y0) .. (x1, y1), the same
    /// at every angle (a two-dimensional table's follow the light from field to field: the first field's).
    double pupilX0 = 0.0, pupilY0 = 0.0;
    double pupilX1 = 0.0, pupilY1 = 0.0;
    std::vector<std::size_t> apertureSteps;      ///< path steps whose clear-aperture margin is stored
    std::size_t stopCrossings = 0;               ///< times the path crosses the stop (hit points stored)
    std::vector<std::vector<ShapedMesh>> meshes; ///< [wavelength][angle]

    /// Floats per vertex: x, y (sensor mm), weight, the apertures' margins, the stop hits' x, y.
    std::size_t stride() const { return 3 + apertureSteps.size() + 2 * stopCrossings; }
};

struct ShapedTable {
    std::string lensName, lensHash;
    /// The field a rotationally symmetric lens's table spans: angles() field angles uniform over
    /// 0..maxAngleDeg at azimuth 0 (for a two-dimensional table, the largest field angle it holds).
    double maxAngleDeg = 0.0;
    /// An anamorphic lens's field (x > 0): x * y directions of tangents (tx, ty) = tan(angle) x
    /// (-sin azimuth, cos azimuth) (trace::Field: the side of the axis its direct image lands on)
    /// uniform over 0..maxTanX and 0..maxTanY, the meshes [wavelength][iy * x + ix].
    struct FieldGrid {
        int x = 0, y = 0;
        double maxTanX = 0.0, maxTanY = 0.0;
    } fieldGrid;
    std::vector<double> wavelengthsNm;
    double sensorZ = 0.0;                     ///< mm from the first vertex
    std::pair<double, double> sensorSizeMm;   ///< the sensor the table covers
    double pupilRadiusMm = 0.0;               ///< the paraxial entrance pupil's (d line)
    std::vector<std::vector<double>> directY; ///< [wavelength][angle] the direct image's centroid, mm
    /// A two-dimensional table's direct image flux per [wavelength][field] (pupil mm^2 x weight): its
    /// meshes' weights are relative to it, and a light between fields is normalised by its
    /// interpolation (where vignetting dims the direct image steeply, interpolated ratios are not).
    std::vector<std::vector<double>> directFlux;
    /// What the fitted models use, derived from the meshes (fitShapedTable, ghost_table.h): every
    /// stored ghost's flux, moments and fits at the table's angles, in the same order as `ghosts`.
    GhostTable fitted;
    trace::Iris iris; ///< the lens's iris at the working opening (d line)
    std::vector<ShapedGhost> ghosts;
    std::size_t ghostCount = 0; ///< every two-bounce ghost of the lens, stored or not
    std::size_t rays = 0;       ///< rays traced to build the table
    double buildSeconds = 0.0;

    /// True for an anamorphic lens's table (over the fieldGrid).
    bool twoDimensional() const { return fieldGrid.x > 0; }
    /// Fields stored per ghost and wavelength: the angles, or the grid's x * y.
    int angles() const { return ghosts.empty() ? 0 : static_cast<int>(ghosts.front().meshes.front().size()); }
    double angleStep() const { return angles() > 1 ? maxAngleDeg / (angles() - 1) : 0.0; }
    /// Whether the table holds the field (within 1e-9 of its extent): its angle at most maxAngleDeg,
    /// or its tangents' magnitudes at most the grid's.
    bool covers(const trace::Field& field) const;
    /// Bytes held by the meshes.
    std::size_t bytes() const;
};

/// Traces the table's meshes, without its fits (buildShapedTable, ghost_table.h, makes both). Progress
/// counts the ghosts traced, of twice their number (the fits are the second half).
ShapedTable traceShapedTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress = {});

/// Every input of the table's build as text, the lens's hash and zoom position included: the cache's
/// key (shaped_cache.h) and the fitted table's settings key.
std::string shapedCacheKey(const optics::Lens& lens, const TableSettings& settings);

/// A light for the shaped renderer: its field (trace::fieldForSensorPoint) and RGB flux.
struct ShapedLight {
    trace::Field field;
    std::array<double, 3> flux{1.0, 1.0, 1.0};
};

struct ShapedRenderSettings {
    /// Per light, the faintest ghosts are dropped while together they hold at most this share of
    /// its ghost flux (summed over the channels).
    double cullShare = 0.005;
    /// Each cell of a ghost's mesh is drawn as k x k sub-cells placed by bicubic interpolation of
    /// the grid, k (at most maxSubdivision) the largest of two rules stated in pixels
    /// (docs/ghost-table.md, "Subdivision in pixels"). Where light lands: the flat sub-cells, and the
    /// aperture edges cutting them, lie within flatnessPx pixels of the bicubic surface for the
    /// ghost instance of highest mean irradiance in the frame, growing in inverse proportion to a
    /// ghost's irradiance up to maxFlatnessPx (its share of the image's squared error is its
    /// irradiance squared times the area its misplaced edges sweep); where the bicubic stencil is
    /// incomplete (the grid's border, lost rays) cells cut by an edge get sub-cells of about
    /// subcellPx pixels. How it is spread: the error the elements' density leaves in a pixel is at
    /// most irradianceError times the instance's brightest pixel for the instance of highest mean
    /// irradiance, growing with a dimmer one's as its flatness does (the same absolute error) —
    /// second order in the sub-cell's size for linear elements, first order for uniform ones, and no
    /// sub-cell below a quarter pixel. The hybrid's gridded instances are drawn uniform.
    /// Each triangle's density is linear over it (linearDensity), the plane through its vertices'
    /// irradiances (the mesh's weight over the Jacobian of its interpolating surface) with its flux
    /// kept, where it covers at least a pixel; below that, and with linearDensity false, uniform.
    bool linearDensity = true;
    double flatnessPx = 0.02;
    double irradianceError = 0.002;
    double maxFlatnessPx = 1.0;
    double subcellPx = 2.0;
    int maxSubdivision = 8;

    /// The hybrid (docs/fourier.md, "Shaped ghosts through the series"): with a grid (step > 0) and
    /// a budget, the instances whose estimated error on the grid is smallest are drawn onto it
    /// instead of the frame, as many as keep the estimated relative L2 error of every channel of
    /// the flare within gridError; the caller takes the grid to the frame (its Fourier series).
    double gridError = 0.0;     ///< 0: every instance drawn directly
    double gridFlatness = 0.25; ///< the gridded instances' tolerance, in grid cells
    struct Grid {
        int step = 0;              ///< cell size, frame pixels (0: no grid)
        int width = 0, height = 0; ///< cells
        double x0 = 0.0, y0 = 0.0; ///< frame pixels of the first cell's top-left corner
    } grid;
};

struct ShapedRender {
    std::array<std::vector<double>, 3> channel; ///< frame-sized, row-major, flux per pixel
    std::size_t drawn = 0, culled = 0;          ///< ghost instances (ghost x light)
    double culledShare = 0.0;                   ///< largest share of a light's ghost flux culled
    double deposited = 0.0, offImage = 0.0;     ///< flux summed over the channels
    std::size_t triangles = 0;
    /// Triangles per pixel they cover (ShapedPolygons::areaPx), the mean over the instances drawn
    /// directly and their channels: what the subdivision costs against what it draws.
    double trianglesPerPixel = 0.0, mostTrianglesPerPixel = 0.0; ///< the mean, the largest
    /// The gridded instances (ShapedRenderSettings::gridError): their cell integrals on the grid,
    /// row-major, and the error their route is estimated to add, relative to each channel's L2 norm
    /// (the largest channel's).
    std::array<std::vector<double>, 3> grid;
    std::size_t gridded = 0, gridTriangles = 0;
    double gridTrianglesPerCell = 0.0; ///< the same for the gridded instances, per grid cell
    double gridErrorEstimate = 0.0;
};

/// The hybrid's split: per instance, the squared error its route through the grid adds to each
/// channel; per channel, the squared error allowed. Taken in increasing order of their largest share
/// of a channel's budget (ties by index), instances go onto the grid (1) while every channel's sum
/// stays <= its budget (an instance that reaches it exactly goes); the first that does not fit, and
/// every one after it, is drawn directly (0). `spent`: each channel's sum on the grid.
std::vector<char> chooseGridded(const std::vector<std::array<double, 3>>& error2, const std::array<double, 3>& budget,
                                std::array<double, 3>& spent);

/// Squared L2 error that drawing an edge of unit irradiance jump and `length` pixels onto a grid of
/// `step` pixels, and keeping the grid's series below its Nyquist frequency, adds: (2 / pi^2) x
/// length x step (the edge's spectrum beyond the Nyquist frequency and about as much aliased back;
/// docs/fourier.md). renderShaped weighs each side of an instance's mesh cells by its jump squared.
double gridErrorSquared(double length, double step);

/// A ghost between two of the table's angles: a0 and a0 + 1, at fraction t. In a two-dimensional
/// table (ShapedTable::FieldGrid), between its fields (a0, b0) and (a0 + 1, b0 + 1) of the grid's x
/// and y, at fractions t and s.
struct MeshInstance {
    std::size_t ghost = 0;
    int a0 = 0;
    double t = 0.0;
    double flatnessPx = 0.0; ///< the subdivision's tolerance (ShapedRenderSettings::flatnessPx)
    /// the tolerance where an aperture's edge crosses a cell (0: flatnessPx)
    double edgeFlatnessPx = 0.0;
    /// the largest error the elements' density may leave in a pixel, relative to the instance's
    /// brightest pixel (ShapedRenderSettings::irradianceError; infinity: none)
    double irradianceError = std::numeric_limits<double>::infinity();
    /// Every decimation-th vertex of the mesh on each axis (a divisor of the ghost's grid): cells
    /// of decimation^2 cells, for a grid coarser than the mesh (ShapedRenderSettings::grid).
    int decimation = 1;
    int b0 = 0;
    double s = 0.0;
};

/// Where a light puts the table's ghosts: their landing points turned by azimuthRad, then mirrored
/// (x times mirrorX, y times mirrorY, each +-1), and the iris seen from the table's frame the
/// inverse way (a light in another quadrant of a two-dimensional table is the mirror image of one
/// in the table's).
struct Placement {
    double azimuthRad = 0.0;
    double mirrorX = 1.0, mirrorY = 1.0;
};

/// The lights and instances of a frame for a raster that cuts the table's meshes itself
/// (PolygonRaster::drawMeshes): each instance is ghost `mesh.ghost` of light `light`.
struct MeshLight {
    Placement placement;
    std::array<double, 3> flux{}; ///< per channel
};
struct MeshDraw {
    std::size_t light = 0;
    MeshInstance mesh;
};
/// What one instance drew at one wavelength: meshPolygons' ShapedPolygons' energy, areaPx and triangles.
struct MeshDrawn {
    double energy = 0.0, areaPx = 0.0;
    std::size_t triangles = 0;
};

/// Where renderShaped draws its polygons when not on the CPU (whose trace::CoverageRaster is the
/// reference): the same exact pixel-area coverage, each channel the sum of its polygons.
class PolygonRaster {
  public:
    virtual ~PolygonRaster() = default;
    /// Starts `channels` zero images of the frame's size. energyBound bounds the energy any one
    /// pixel can receive (the sum of the polygons' energies does).
    virtual void begin(const trace::ImageFrame& frame, std::size_t channels, double energyBound) = 0;
    /// Adds the polygons to channel c.
    virtual void draw(std::size_t c, const ShapedPolygons& polygons) = 0;
    /// The channels (frame-sized, row-major, flux per pixel).
    virtual std::vector<std::vector<double>> finish() = 0;
    /// Whether drawMeshes takes this table (otherwise renderShaped cuts the meshes and calls draw).
    virtual bool cutsMeshes(const ShapedTable&) const { return false; }
    /// Cuts every instance's mesh at wavelengths 0 .. channels - 1 into channel w as renderShaped
    /// does on the CPU (the same polygons, to rounding) and adds them, a polygon narrower than
    /// splatBelow pixels on both axes (0: none) as a bilinear splat at its vertices' mean; per
    /// instance and channel, instance-major, what it drew. Only for a table cutsMeshes takes.
    virtual std::vector<MeshDrawn> drawMeshes(const ShapedTable& table, const std::vector<MeshLight>& lights,
                                              const std::vector<MeshDraw>& draws, std::size_t channels,
                                              const ShapedRenderSettings& settings, float splatBelow = 0.0f);
};

/// Draws every light's ghosts into the frame; channel c is the table's wavelength c. The polygons
/// are drawn on the CPU, or by `raster` when one is given.
ShapedRender renderShaped(const ShapedTable& table, const std::vector<ShapedLight>& lights,
                          const trace::ImageFrame& frame, const ShapedRenderSettings& settings = {},
                          PolygonRaster* raster = nullptr);

} // namespace ff::ghosts
