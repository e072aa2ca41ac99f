#pragma once
// The ghost table's data (ghost_table.h builds it): its settings, one fitted ghost per wavelength at
// each of a ghost's field angles (TableEntry), each ghost's angles and entries, what the build
// measured, and the table with its lookup. Lengths in mm on the sensor, flux relative to the direct
// image at the same wavelength.

#include "ghosts/ghost_fit.h"
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

    /// The settings from the choices' names (trace::samplingNamed, sensorPlaneNamed, coatingNamed),
    /// each value checked against its documented range (ff::Error, Usage, naming the Python
    /// argument and the CLI option): grid 4..512 rays per
    /// side, maxAngleDeg 0..85 (0: the default), maxAngles 9..513, tolerance 1e-6..1.
    static TableSettings named(int grid, const std::string& sampling, const std::string& sensor,
                               const std::string& coating, double maxAngleDeg, int maxAngles, double tolerance);
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

} // namespace ff::ghosts
