#pragma once
// First-order (paraxial) optics by a y-nu trace: heights y (mm) and reduced angles w = n u.
//   refraction at surface i:  w' = w - y c_i (n' - n)
//   transfer to the next:     y_next = y + t_i w' / n'
// Focal lengths come from two base rays; the pupils are the paraxial images of the stop, found by
// tracing from the stop (not assumed). All z positions are measured along +z.

#include "optics/lens.h"

#include <limits>

namespace ff::optics {

/// Paraxial ray state in the medium after a surface (or in object space before the first one).
struct ParaxialRay {
    double y = 0.0; ///< height, mm
    double w = 0.0; ///< reduced angle n*u
};

struct FirstOrder {
    double lambdaNm = 0.0;
    double efl = 0.0;            ///< effective focal length, mm (1 / power)
    double bfd = 0.0;            ///< last vertex to the rear focal point, mm
    double ffd = 0.0;            ///< front focal point to the first vertex, mm (> 0: in front of it)
    double entrancePupilZ = 0.0; ///< from the first vertex (> 0: behind it)
    double entrancePupilDiameter = 0.0;
    double exitPupilZ = 0.0; ///< from the last vertex (< 0: in front of it); +-inf if telecentric
    double exitPupilDiameter = 0.0;
    double fNumber = 0.0;                 ///< efl / entrance-pupil diameter
    double stopSemiAperture = 0.0;        ///< working stop opening used (see workingStopSemiAperture)
    double totalTrack = 0.0;              ///< first vertex to the sensor
    double imageDistance = 0.0;           ///< last vertex to the sensor (the last thickness)
    std::size_t reflectingInterfaces = 0; ///< surfaces with an index step at lambdaNm
    std::size_t ghostCount = 0;           ///< two-bounce ghosts: m (m - 1) / 2
    bool afocal = false;                  ///< zero power: efl, bfd, ffd and fNumber are +inf
    double angularMagnification = 0.0;    ///< afocal only: u' / u of a ray through the first vertex
};

/// Traces a paraxial ray that enters surface `from` with state `in` (in the medium before it)
/// through surfaces [from, to), returning the state after surface to-1 at its vertex plane.
ParaxialRay traceParaxial(const Lens& lens, double lambdaNm, ParaxialRay in, std::size_t from, std::size_t to);

/// Height reached at the vertex plane of surface `at` by a ray entering surface `from`.
double heightAt(const Lens& lens, double lambdaNm, ParaxialRay in, std::size_t from, std::size_t at);

/// Paraxial effective focal length at lambdaNm (throws ff::Error Input for an afocal system).
double paraxialEfl(const Lens& lens, double lambdaNm);
/// Last vertex to the paraxial rear focal point at lambdaNm.
double paraxialBfd(const Lens& lens, double lambdaNm);

/// The stop opening (semi-aperture, mm) the lens works at: the stop's own semi-aperture, or the one
/// that gives the header's f-number at the d line. If the f-number asks for more than the stop's
/// clear aperture, it is clamped and `clamped` is set. Throws when neither is known.
double workingStopSemiAperture(const Lens& lens, bool* clamped = nullptr);

/// Full first-order analysis at lambdaNm. An afocal lens (zero power) throws ff::Error (Input) unless
/// allowAfocal, where its focal data are +inf and its angular magnification is given.
FirstOrder analyzeFirstOrder(const Lens& lens, double lambdaNm, bool allowAfocal = false);

/// The lens as one section sees it: every surface rotationally symmetric with that section's
/// curvature and conic (a rotationally symmetric lens is returned as it is). Its first-order data are
/// the section's (analyzeFirstOrder(sectionOf(lens, Section::X), ...)).
Lens sectionOf(const Lens& lens, Section section);

/// The anamorphic squeeze, EFL of the y-z section / EFL of the x-z section at lambdaNm: how much wider
/// the field is in x than the frame's aspect shows (1 for a rotationally symmetric lens; throws
/// ff::Error Input where a section is afocal).
double squeeze(const Lens& lens, double lambdaNm);

/// Sets the last thickness to the paraxial back focal distance at the d line.
void focusAtParaxialImage(Lens& lens);

} // namespace ff::optics
