#pragma once
// The ghost report of a lens at one field angle (a lens designer's ghost-focus table): for the direct
// image and every two-bounce ghost, per wavelength, how much light gets through and where it lands.
//
// Energies: each launched ray carries its pupil cell's area; a path's energy is the sum of
// weight x cell area over its rays, reported relative to the direct path's energy at the same
// wavelength. Statistics are over the unbounded sensor plane (mm, sensor coordinates: +y is where
// the direct image of a field at azimuth 0 lands); onSensor is the share of the energy that falls
// inside the sensor rectangle centred on the axis.

#include "core/reporter.h"
#include "optics/lens.h"
#include "trace/pupil_sampling.h"
#include "trace/sensor.h"

#include <optional>
#include <string>
#include <vector>

namespace ff::trace {

struct GhostAnalysisOptions {
    Field field;
    std::vector<double> wavelengthsNm = {550.0};
    Sampling sampling = Sampling::Reaim;
    int grid = 64;
    SensorPlane sensor = SensorPlane::File;
    CoatingChoice coating = CoatingChoice::File;
    std::pair<double, double> sensorSizeMm = {36.0, 24.0}; ///< used when the lens gives none
};

struct PathStats {
    std::optional<GhostPair> ghost; ///< empty for the direct image
    std::size_t launched = 0, surviving = 0, blocked = 0;
    double energy = 0.0;                     ///< sum of weight x cell area (mm^2)
    double relativeEnergy = 0.0;             ///< energy / direct energy
    double energyPerRay = 0.0;               ///< relative energy / launched rays
    double centroidX = 0.0, centroidY = 0.0; ///< energy-weighted, mm on the sensor
    double rmsRadius = 0.0;                  ///< about the centroid, mm
    double axialRatio = 0.0;                 ///< centroid y / direct centroid y (NaN on axis)
    double onSensor = 0.0;                   ///< share of the energy inside the sensor rectangle
    std::string label() const { return ghost ? ghost->label() : std::string("direct"); }
};

struct WavelengthReport {
    double lambdaNm = 0.0;
    PathStats direct;
    std::vector<PathStats> ghosts; ///< sorted by energy, largest first
    double totalGhostRelative = 0.0;
};

struct GhostReport {
    double sensorZ = 0.0;
    std::pair<double, double> sensorSizeMm;
    std::size_t reflectingInterfaces = 0;
    std::vector<WavelengthReport> wavelengths;
};

GhostReport analyzeGhosts(const optics::Lens& lens, const GhostAnalysisOptions& options);

} // namespace ff::trace
