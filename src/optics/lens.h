#pragma once
// A lens prescription: surfaces front (object side) to back, with header data and provenance.
// All lengths in mm. The sensor sits `surfaces.back().thickness` behind the last vertex.

#include "optics/coating_spec.h"
#include "optics/surface.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ff::optics {

struct Lens {
    // --- description and provenance ---
    std::string name;
    std::string source; ///< where the numbers come from (publication, sample, database)
    std::string patent;
    std::string file;            ///< path it was read from (for messages)
    std::string contentHash;     ///< hash of the file's bytes (cache keys, output metadata)
    std::string format = "lens"; ///< lens | zmx | dat: the format it was read from

    // --- header data (all optional) ---
    std::optional<double> nominalFocalLength;          ///< as stated by the file; informational only
    std::optional<double> fNumber;                     ///< working f-number (sets the stop opening)
    std::optional<std::pair<double, double>> sensorMm; ///< width x height, mm
    int apertureBlades = 0;                            ///< iris blades; 0 = circular
    double bladeRotationDeg = 0.0;
    std::optional<CoatingSpec> defaultCoating; ///< lens-wide coating of coated surfaces

    // --- surfaces ---
    std::vector<Surface> surfaces;
    bool imageDistanceAuto = false; ///< last thickness was 'auto' (or 0): the paraxial focus at the d line
    bool stopInferred = false;      ///< no stop row: the stop is the surface that limits the axial beam

    // --- zoom ---
    std::vector<std::string> zoomLabels;       ///< empty for a prime lens
    std::vector<std::vector<double>> zoomGaps; ///< per surface: thickness per position (or empty)
    std::size_t activeZoom = 0;

    std::size_t zoomCount() const { return zoomLabels.empty() ? 1 : zoomLabels.size(); }
    bool isZoom() const { return !zoomLabels.empty(); }

    /// Index of the aperture stop (a validated lens has exactly one).
    std::size_t stopIndex() const;
    /// Medium in front of surface i (air for the first surface).
    const Medium& mediumBefore(std::size_t i) const;
    /// z of surface i's vertex, measured from the first vertex.
    double vertexZ(std::size_t i) const;
    /// z of the sensor plane, from the first vertex (= total track).
    double sensorZ() const;
    /// The coating surface i carries: its explicit spec, or from the FlareSim column (0 bare;
    /// >= 1 the lens-wide `coating:`, else single-layer MgF2 for 1 and a broadband stack for >= 2).
    /// Column and lens-wide coatings apply to glass-air surfaces only; cemented surfaces are bare.
    CoatingSpec coatingOf(std::size_t i) const;
    /// True when no surface has an anamorphic shape.
    bool rotationallySymmetric() const;

    /// Indices of surfaces where the index changes at lambdaNm (these can reflect ghosts).
    std::vector<std::size_t> reflectingInterfaces(double lambdaNm) const;
};

} // namespace ff::optics
