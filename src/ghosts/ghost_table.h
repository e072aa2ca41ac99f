#pragma once
// The ghost table of a lens: every two-bounce ghost fitted (ghost_fit.h) per wavelength over field
// angles 0..thetaMax, so that a light anywhere in the frame costs a lookup, not a trace.
//
// Every ghost starts on 9 uniform field angles and then refines its own: the builder measures, for
// each of a ghost's intervals, the error of linear interpolation at its mid-angle against a direct
// trace (centroid relative to max(|centroid|, sigma, 1 % of the sensor half-height), sigma relative to
// itself, at wavelengths where the ghost carries at least 1 % of the strongest ghost's flux there)
// and keeps the mid-angle as a new entry of that ghost; only intervals above the tolerance are split
// further, so a ghost's angles gather where it changes fast (its vignetting onsets), until every
// interval passes, reaches the finest step (1/131072 of the field) or the budget (maxAngles traces per
// ghost on average) is spent; when the budget cannot take every failing interval, those with the
// largest error x width go first, whichever ghost they belong to. A mid-angle's pupil search looks
// where its neighbours' searches found light; where it finds light that a neighbour's search lacks
// and looking there finds it, the neighbour is traced again (its other interval then measured again),
// so that a piece of light one search stepped over is not lost between angles where another met it. The measured errors
// (median, 95th percentile, worst over the final intervals of ghosts that counted there) are stored with the table; an
// interval whose halves could not be measured counts with its own error.
//
// Each entry counts the light landing within twice the sensor's half-diagonal of the axis (grazing
// rays that land metres away can never reach the frame and would dominate the moments).
// Geometry follows the tracer: the source at azimuth 0, its direct image at +y; a ghost's centre is
// m x (direct image position), m = ghost centroid y / direct centroid y. Lengths in mm on the sensor,
// flux relative to the direct image at the same wavelength.

#include "ghosts/ghost_fit.h"
#include "optics/lens.h"
#include "trace/ghost_analysis.h"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace ff::ghosts {

struct TableSettings {
    std::vector<double> wavelengthsNm = {650.0, 550.0, 450.0}; ///< R, G, B
    trace::Sampling sampling = trace::Sampling::Reaim;
    int grid = 32;
    trace::SensorPlane sensor = trace::SensorPlane::File;
    trace::CoatingChoice coating = trace::CoatingChoice::File;
    double maxAngleDeg = 0.0; ///< 0: the field of the sensor's half-diagonal plus 5 %
    double interpolationTolerance = 0.005;
    int maxAngles = 64; ///< the refinement's budget: traced entries per ghost, on average
    /// Cells on a vignetting edge are re-traced on this many sub-cells per side for the moments, each
    /// sub-ray standing for its sub-cell's lit share (1: off; dark cells get twice as many, steps in
    /// the weight four times): without it the moments move in steps as edges cross grid cells, and
    /// that noise, not the optics, would set the interpolation error.
    int edgeSubdivisions = 4;
    std::pair<double, double> sensorSizeMm = {36.0, 24.0}; ///< used when the lens gives none

    /// Every setting that changes the table, as text (part of the cache key).
    std::string key() const;
};

struct TableEntry {
    double centroidY = 0.0;            ///< mm (the centroid's x is 0 by symmetry)
    double sigmaR = 0.0, sigmaT = 0.0; ///< moment spreads, mm
    double flux = 0.0;                 ///< relative to the direct image
    double surviving = 0.0;            ///< surviving fraction of launched rays
    ProfileFit gaussian, cos2;
};

struct TableGhost {
    trace::GhostPair pair;
    std::vector<double> anglesDeg;                ///< this ghost's field angles, increasing, from 0
    std::vector<std::vector<TableEntry>> entries; ///< [wavelength][angle]
};

/// Where a build spent its traces (entries traced, traced again too) and its time, by step of the
/// refinement: the 9 starting angles, the mid-angles of intervals wider than the finest step, the
/// neighbours traced again where a mid-angle found light they lacked, and at the finest step the
/// pieces carried between neighbouring entries, the knots at kinks (each with the looks deciding
/// whether tracing again finds light) and the ghosts traced again on finer grids. Reported by the
/// builder, not stored with the table.
struct BuildReport {
    struct Step {
        std::size_t traces = 0;
        double seconds = 0.0;
    };
    /// The interval whose interpolation error is the table's worst.
    struct Interval {
        std::string ghost;
        double fromDeg = 0.0, toDeg = 0.0, error = 0.0;
    };
    Step start, midAngles, neighbours, carried, knots;
    Step finer;                  ///< entries of ghosts traced again on finer grids
    std::size_t finerGhosts = 0; ///< ghosts whose grids were refined
    Interval worst;
    std::size_t budget = 0; ///< traces the build could spend
    std::size_t rounds = 0; ///< rounds of the refinement after the start
    bool budgetSpent = false;

    std::size_t traces() const {
        return start.traces + midAngles.traces + neighbours.traces + carried.traces + knots.traces + finer.traces;
    }
};

struct GhostTable {
    int schemaVersion = 2;
    std::string lensName, lensFile, lensHash, settingsKey;
    double efl = 0.0, sensorZ = 0.0;
    std::pair<double, double> sensorSizeMm;
    int apertureBlades = 0;
    double bladeRotationDeg = 0.0;
    std::vector<double> wavelengthsNm;
    std::vector<double> anglesDeg;            ///< every ghost's angles together, increasing, from 0
    std::vector<std::vector<double>> directY; ///< [wavelength][angle] direct image centroid, mm
    std::vector<TableGhost> ghosts;
    /// Measured at the last refinement's mid-angles (before they joined the table, so an upper
    /// estimate for the final table): median, 95th percentile and largest relative error.
    double interpolationError = 0.0, interpolationErrorMedian = 0.0, interpolationErrorP95 = 0.0;
    /// The share of those intervals' field (their angular widths summed) within the tolerance: the
    /// chance that a light, placed at random, meets a ghost that interpolates within it.
    double withinTolerance = 1.0;
    double buildSeconds = 0.0;
    BuildReport build; ///< where the build's traces and time went (empty for a table read back)

    /// Linear interpolation of a ghost's entry at angleDeg between its own angles (clamped to them).
    /// Where the ghost is dark at one end of the interval, it keeps the lit end's shape (centroid,
    /// widths) and only its flux (and peaks) fade linearly to zero.
    TableEntry at(std::size_t ghost, std::size_t wavelength, double angleDeg) const;
    /// Direct image height at angleDeg, interpolated.
    double directAt(std::size_t wavelength, double angleDeg) const;
    /// Magnification m = ghost centroid / direct image height (on the axis, at the ghost's first non-zero angle).
    double magnification(std::size_t ghost, std::size_t wavelength, double angleDeg) const;
    /// Index of the table wavelength nearest to lambdaNm.
    std::size_t nearestWavelength(double lambdaNm) const;
    /// The wavelengths standing for R, G, B: those nearest to 650, 550 and 450 nm.
    std::array<std::size_t, 3> rgbChannels() const;
    /// Traced entries per wavelength: the sum of the ghosts' angle counts.
    std::size_t entryCount() const;
};

/// Called with (done, total) work units while building; may be empty.
using Progress = std::function<void(std::size_t, std::size_t)>;

/// Builds the table (parallel over ghosts x angles). Throws ff::Error (Input) for an anamorphic lens.
GhostTable buildGhostTable(const optics::Lens& lens, const TableSettings& settings, const Progress& progress = {});

/// What the table would hold at each of the given field angles, traced directly as the builder
/// traces its entries: [angle][ghost][wavelength], ghosts in the table's order, or only those whose
/// labels are given, in that order (an unknown label is an error). For checking a table's
/// interpolation against direct traces.
std::vector<std::vector<std::vector<TableEntry>>> traceEntries(const optics::Lens& lens, const TableSettings& settings,
                                                               const std::vector<double>& anglesDeg,
                                                               const std::vector<std::string>& onlyGhosts = {});

} // namespace ff::ghosts
