#pragma once
// Compact analytic ghosts from shaped ones. From a ghost's clipped mesh polygons (polygons.h: each of
// uniform density, as the shaped renderer draws them) this measures its flux, centroid and second
// moments exactly (closed forms over each polygon), and fits two separable profiles to its image: a
// Gaussian (sigma per axis) and a cos^2 bump (half-width w per axis), each moment-matched first
// (sigma; w = 2.766 sigma) then refined by least squares against the polygons drawn into a local
// image by the coverage raster.
//
// Frame: fits are made with the source at azimuth 0, so the radial direction is +y on the sensor and
// the tangential one is x; widths are in mm. A profile is scaled so that its integral equals the
// ghost's flux: a fit never invents or loses energy. The fit error is the relative L2 distance
// between the fitted profile and the ghost's image, over a square of +-4 sigma around the centroid
// (64 x 64 pixels by default).

#include "ghosts/polygons.h"
#include "trace/flare_raster.h"

#include <string_view>

namespace ff::ghosts {

enum class Profile { Gaussian, Cos2 };
const char* toString(Profile p);
/// The profile toString names; any other name throws ff::Error (Usage) naming `what`.
Profile profileNamed(std::string_view name, std::string_view what = "the profile");

/// Unit-peak separable profile at offsets (u radial, v tangential) from its centre.
double profileValue(Profile p, double widthR, double widthT, double u, double v);
/// Integral of the unit-peak profile over the plane: 2 pi sR sT (Gaussian), wR wT (cos^2).
double profileArea(Profile p, double widthR, double widthT);

struct ProfileFit {
    double widthR = 0.0, widthT = 0.0; ///< Gaussian sigma or cos^2 half-width, mm
    double peak = 0.0;                 ///< flux per mm^2 at the centre (= flux / area)
    double error = 0.0;                ///< relative L2 against the ghost's image
};

/// Energy and moments of polygons of uniform density, in sensor mm (+y up).
struct PolygonMoments {
    double energy = 0.0;
    double centroidX = 0.0, centroidY = 0.0;
    double mxx = 0.0, myy = 0.0, mxy = 0.0; ///< central second moments, mm^2
};

/// The polygons' moments: each polygon's area integrals of 1, x, y, x^2, y^2, xy by Green's theorem
/// (exact for straight edges), times its density. `frame` maps their pixel coordinates to the sensor.
/// A polygon of zero area counts as a point at its vertices' mean. With maxRadiusMm > 0 only polygons
/// whose vertex mean lies within it of the axis count.
PolygonMoments polygonMoments(const ShapedPolygons& polygons, const trace::ImageFrame& frame, double maxRadiusMm = 0.0);

struct GhostFit {
    double flux = 0.0;                       ///< energy of the polygons that count
    double centroidX = 0.0, centroidY = 0.0; ///< mm on the sensor
    double sigmaR = 0.0, sigmaT = 0.0;       ///< RMS spreads about the centroid along y and x, mm
    double covRT = 0.0;                      ///< mixed second moment, mm^2
    ProfileFit gaussian, cos2;
};

struct FitOptions {
    int imageSize = 64;        ///< pixels per side of the local image the profiles are fitted to
    double extentSigmas = 4.0; ///< half-side of that image in units of the larger moment spread
    /// Only light landing within this distance of the axis counts (0 = all): rays that leave at
    /// grazing angles land metres away, can never reach the frame, and would dominate the moments.
    double maxRadiusMm = 0.0;
};

/// Fits one ghost drawn as `polygons` in `frame`'s pixels. A ghost with no energy gets a zero fit.
GhostFit fitGhost(const ShapedPolygons& polygons, const trace::ImageFrame& frame, const FitOptions& options = {});

} // namespace ff::ghosts
