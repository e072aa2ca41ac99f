#pragma once
// Compact analytic ghosts from traced ones. From a ghost's traced bundle (centre and corner rays, as
// for the traced renderer) this measures its flux, centroid and second moments, and fits two separable
// profiles to its traced irradiance: a Gaussian (sigma per axis) and a cos^2 bump (half-width w per
// axis), each moment-matched first (sigma; w = 2.766 sigma) then refined by least squares.
//
// Frame: fits are made with the source at azimuth 0, so the radial direction is +y on the sensor and
// the tangential one is x; widths are in mm. A profile is scaled so that its integral equals the
// ghost's traced flux: a fit never invents or loses energy. The fit error is the relative L2 distance
// between the fitted profile and the traced image, over a square of +-4 sigma around the centroid.

#include "trace/bundle_moments.h"
#include "trace/embree_tracer.h"
#include "trace/pupil_sampling.h"

#include <span>
#include <vector>

namespace ff::ghosts {

enum class Profile { Gaussian, Cos2 };
const char* toString(Profile p);

/// Unit-peak separable profile at offsets (u radial, v tangential) from its centre.
double profileValue(Profile p, double widthR, double widthT, double u, double v);
/// Integral of the unit-peak profile over the plane: 2 pi sR sT (Gaussian), wR wT (cos^2).
double profileArea(Profile p, double widthR, double widthT);

struct ProfileFit {
    double widthR = 0.0, widthT = 0.0; ///< Gaussian sigma or cos^2 half-width, mm
    double peak = 0.0;                 ///< flux per mm^2 at the centre (= flux / area)
    double error = 0.0;                ///< relative L2 against the traced image
};

struct GhostFit {
    double flux = 0.0;                       ///< sum of the representing rays' energies (scaled)
    double centroidX = 0.0, centroidY = 0.0; ///< mm on the sensor
    double sigmaR = 0.0, sigmaT = 0.0;       ///< RMS spreads about the centroid along y and x, mm
    double covRT = 0.0;                      ///< mixed second moment, mm^2
    double survivingFraction = 0.0;          ///< surviving / launched rays
    ProfileFit gaussian, cos2;
};

struct FitOptions {
    int imageSize = 64;        ///< pixels per side of the local image the profiles are fitted to
    double extentSigmas = 4.0; ///< half-side of that image in units of the larger moment spread
    /// Only light landing within this distance of the axis counts (0 = all): rays that leave at
    /// grazing angles land metres away, can never reach the frame, and would dominate the moments.
    double maxRadiusMm = 0.0;
};

/// Fits one ghost. energyScale multiplies every ray's weight x cell area (e.g. 1 / direct energy).
/// Flux, moments and fits all use the rays that count (see FitOptions::maxRadiusMm). A ghost with no
/// such ray gets a zero fit. `moments`, when given, are the bundle's moments measured by the caller
/// (e.g. trace::measureBundleResolved, with the same scale and radius); else the grid's are used.
GhostFit fitGhost(const trace::Bundle& centres, const std::vector<trace::RayResult>& centreHits,
                  const std::vector<trace::RayResult>& cornerHits, double energyScale, const FitOptions& options = {},
                  const trace::BundleMoments* moments = nullptr);

/// One traced part of a ghost's pupil (trace::pupilParts): its grid and the hits of its centre and
/// corner rays.
struct BundlePart {
    const trace::Bundle* centres = nullptr;
    const std::vector<trace::RayResult>* centreHits = nullptr;
    const std::vector<trace::RayResult>* cornerHits = nullptr;
};

/// Fits a ghost traced in parts, each on its own grid (their squares of the pupil plane disjoint):
/// flux and moments are those of all the parts together (trace::combineMoments, unless `moments` is
/// given), and every part is drawn into the image the profiles are fitted to.
GhostFit fitGhost(std::span<const BundlePart> parts, double energyScale, const FitOptions& options = {},
                  const trace::BundleMoments* moments = nullptr);

} // namespace ff::ghosts
