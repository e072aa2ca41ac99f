#pragma once
// The sensor's concepts: where its plane lies (the lens file's or the paraxial focus), the coating
// choice a flare is traced with, and the field whose direct image lands at a point of the sensor.

#include "optics/lens.h"
#include "trace/pupil_sampling.h"

#include <string>
#include <utility>

namespace ff::trace {

enum class SensorPlane { File, Paraxial };
enum class CoatingChoice { File, None, MgF2 };

/// The choices by the names the CLI and the Python module give them; any other name throws ff::Error
/// (Usage) listing the names.
Sampling samplingNamed(const std::string& name);       ///< reaim | paraxial-grid
SensorPlane sensorPlaneNamed(const std::string& name); ///< file | paraxial
CoatingChoice coatingNamed(const std::string& name);   ///< file | none | mgf2

/// z of the sensor plane from the first vertex: the lens's last thickness, or the paraxial focus at
/// the d line.
double sensorPlaneZ(const optics::Lens& lens, SensorPlane plane);

/// Applies a coating choice to a copy of the lens (None: every surface bare; MgF2: a single MgF2
/// quarter wave at 550 nm on every glass-air surface, cemented ones bare; File: as the lens says).
optics::Lens withCoating(const optics::Lens& lens, CoatingChoice choice);

/// The field whose direct image (its chief ray through the centre of the paraxial entrance pupil,
/// traced exactly at the d line with the apertures open) lands at sensor point (x, y) mm. Throws
/// ff::Error (Input) when no field angle below 89 deg reaches that far.
Field fieldForSensorPoint(const optics::Lens& lens, double sensorZ, double xMm, double yMm);

/// The field angle (deg) that a flare over a sensor of sensorMm (width, height) must reach: the field
/// whose direct image lands 5 % beyond the half-diagonal (fieldForSensorPoint); where no field
/// reaches that far, the paraxial one, atan(1.05 x half-diagonal / EFL), at most 80 deg.
double sensorCornerFieldDeg(const optics::Lens& lens, double sensorZ, std::pair<double, double> sensorMm);

} // namespace ff::trace
