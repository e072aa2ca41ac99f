#pragma once
// The ghost table's settings and its fitted form. The one traced representation of a ghost is the
// shaped table (shaped_ghosts.h): each ghost's pupil mesh per wavelength at uniform field angles.
// Everything a fitted ghost model needs (flux, centroid, spreads, the Gaussian and cos^2 fits) is
// derived from those meshes (ghost_fit.h) and held here, per ghost, wavelength and table angle
// (TableEntry). Lengths in mm on the sensor, flux relative to the direct image at the same wavelength.

#include "ghosts/ghost_fit.h"
#include "trace/ghost_analysis.h"

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ff::ghosts {

/// Every setting of a table's build.
struct TableSettings {
    std::vector<double> wavelengthsNm = {650.0, 550.0, 450.0}; ///< R, G, B
    /// Cells per side of the pupil mesh of the ghost that is most concentrated on the sensor (flux^2 /
    /// area); the others get fewer, growing as that ratio^(1/4), at least 16.
    int grid = 64;
    int angles = 25;          ///< field angles, uniform over 0..maxAngleDeg
    double maxAngleDeg = 0.0; ///< 0: the field of the sensor's half-diagonal plus 5 %
    trace::SensorPlane sensor = trace::SensorPlane::File;
    trace::CoatingChoice coating = trace::CoatingChoice::File;
    /// The sensor the images span, mm (default: the lens file's, else 36 x 24).
    std::optional<std::pair<double, double>> sensorSizeMm;
    /// Ghosts whose flux stays under this share of the strongest ghost's at every angle and
    /// wavelength are not stored.
    double storeFraction = 1e-5;

    /// The settings from the choices' names (trace::sensorPlaneNamed, coatingNamed), each value
    /// checked against its documented range (ff::Error, Usage, naming the Python argument and the CLI
    /// option): grid 4..512 cells per side, angles 2..1024, maxAngleDeg 0..85 (0: the default).
    static TableSettings named(int grid, int angles, const std::string& sensor, const std::string& coating,
                               double maxAngleDeg);
};

struct TableEntry {
    double centroidY = 0.0;            ///< mm (the centroid's x is 0 by symmetry)
    double sigmaR = 0.0, sigmaT = 0.0; ///< moment spreads, mm
    double flux = 0.0;                 ///< relative to the direct image
    double surviving = 0.0;            ///< lit share of the entrance pupil (paraxial, d line)
    ProfileFit gaussian, cos2;
};

/// Linear interpolation weight of angle a between sorted angles: (index, fraction), clamped.
std::pair<std::size_t, double> locate(const std::vector<double>& angles, double a);

/// Linear interpolation of an entry; where the ghost is dark at one end, it keeps the lit end's shape
/// (centroid, widths) and only its flux (and peaks) fade linearly to zero.
TableEntry interpolate(const TableEntry& a, const TableEntry& b, double t);

struct TableGhost {
    trace::GhostPair pair;
    std::vector<double> anglesDeg;                ///< this ghost's field angles, increasing, from 0
    std::vector<std::vector<TableEntry>> entries; ///< [wavelength][angle]
};

struct GhostTable {
    int schemaVersion = 3;
    std::string lensName, lensFile, lensHash, settingsKey;
    double efl = 0.0, sensorZ = 0.0;
    std::pair<double, double> sensorSizeMm;
    int apertureBlades = 0;
    double bladeRotationDeg = 0.0;
    std::vector<double> wavelengthsNm;
    std::vector<double> anglesDeg;            ///< every ghost's angles together, increasing, from 0
    std::vector<std::vector<double>> directY; ///< [wavelength][angle] direct image centroid, mm
    std::vector<TableGhost> ghosts;
    double buildSeconds = 0.0; ///< of the shaped table and its fits

    /// Linear interpolation of a ghost's entry at angleDeg between its own angles (clamped to them).
    TableEntry at(std::size_t ghost, std::size_t wavelength, double angleDeg) const;
    /// Direct image height at angleDeg, interpolated.
    double directAt(std::size_t wavelength, double angleDeg) const;
    /// Magnification m = ghost centroid / direct image height (on the axis, at the ghost's first non-zero angle).
    double magnification(std::size_t ghost, std::size_t wavelength, double angleDeg) const;
    /// Index of the table wavelength nearest to lambdaNm.
    std::size_t nearestWavelength(double lambdaNm) const;
    /// The wavelengths standing for R, G, B: those nearest to 650, 550 and 450 nm.
    std::array<std::size_t, 3> rgbChannels() const;
    /// Entries per wavelength: the sum of the ghosts' angle counts.
    std::size_t entryCount() const;
};

/// Called with (done, total) work units while building; may be empty.
using Progress = std::function<void(std::size_t, std::size_t)>;

} // namespace ff::ghosts
