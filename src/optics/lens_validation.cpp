#include "optics/lens_validation.h"

#include "core/text.h"
#include "core/units.h"
#include "optics/gradient_index.h"
#include "optics/paraxial.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ff::optics {

namespace {

// A graded medium after surface i: not before the sensor, with a thickness and a clear radius, and
// an index above 1 and finite over the element (r to the larger of its surfaces' semi-apertures, z
// over its thickness, 33 x 33 points) from 380 to 780 nm.
void validateGradient(const Lens& lens, std::size_t i) {
    const auto& surfaces = lens.surfaces;
    const Medium& m = surfaces[i].medium;
    const SourceLocation& at = m.gradient->origin.empty() ? surfaces[i].origin : m.gradient->origin;
    if (i + 1 == surfaces.size())
        throwInputError(at, "a graded index after the last surface: the space before the sensor must be homogeneous");
    double thickness = surfaces[i].thickness;
    if (i < lens.zoomGaps.size())
        for (double g : lens.zoomGaps[i]) thickness = std::max(thickness, g);
    if (!(thickness > 0.0))
        throwInputError(at, "a graded element needs a positive thickness, got " + text::roundTrip(thickness));
    const double radius = std::max(surfaces[i].semiAperture, surfaces[i + 1].semiAperture);
    if (!(radius > 0.0))
        throwInputError(at, "a graded element needs a clear semi-aperture on one of its surfaces (both are 0)");
    for (double lambda : {380.0, lines::F, lines::d, lines::C, 780.0}) {
        const GradientField field(m.index(lambda), *m.gradient, lambda, 0.0);
        for (int a = 0; a <= 32; ++a)
            for (int b = 0; b <= 32; ++b) {
                const double r = radius * a / 32.0, z = thickness * b / 32.0;
                const double n = field.index({r, 0.0, z});
                if (!(n > 1.0) || !std::isfinite(n))
                    throwInputError(at, "the graded index is " + text::roundTrip(n) + " at r = " + text::fixed(r, 3) +
                                            " mm, z = " + text::fixed(z, 3) + " mm, " + text::fixed(lambda, 1) +
                                            " nm, inside the element after surface " + std::to_string(i + 1) +
                                            ": it must stay above 1 and finite");
            }
    }
}

} // namespace

void validateLens(Lens& lens, const SourceLocation& section, Reporter& reporter) {
    auto& surfaces = lens.surfaces;
    if (surfaces.empty()) throwInputError(section, "the lens has no surfaces");
    for (std::size_t i = 0; i < surfaces.size(); ++i)
        if (surfaces[i].medium.gradient) validateGradient(lens, i);

    std::optional<std::size_t> stop;
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        if (!surfaces[i].stop) continue;
        if (stop)
            throwInputError(surfaces[i].origin, "a second aperture stop (surface " + std::to_string(i + 1) +
                                                    "); surface " + std::to_string(*stop + 1) + " is already the stop");
        stop = i;
    }
    if (!stop) {
        // The aperture stop is the surface that limits the axial beam: the smallest ratio of clear
        // semi-aperture to the height of the paraxial marginal ray from an axial object at infinity.
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < surfaces.size(); ++i) {
            if (!(surfaces[i].semiAperture > 0.0)) continue;
            const double y = std::abs(heightAt(lens, lines::d, {1.0, 0.0}, 0, i));
            if (!(y > 1e-9) || !std::isfinite(y)) continue;
            if (surfaces[i].semiAperture / y < best) {
                best = surfaces[i].semiAperture / y;
                stop = i;
            }
        }
        if (!stop)
            throwInputError(section,
                            "no aperture stop, and no surface limits the axial beam (no semi-aperture is given): "
                            "mark one surface as the stop (a 'stop' row for a flat stop, or the word 'stop' "
                            "after the columns of a curved surface)");
        surfaces[*stop].stop = true;
        lens.stopInferred = true;
        reporter.note(surfaces[*stop].origin, "no stop row: surface " + std::to_string(*stop + 1) +
                                                  " limits the axial beam (semi-aperture / marginal-ray height " +
                                                  text::fixed(best, 4) +
                                                  ", the smallest) and is taken as the aperture stop");
    }

    Surface& last = surfaces.back();
    const bool lastZoomed = surfaces.size() <= lens.zoomGaps.size() && !lens.zoomGaps[surfaces.size() - 1].empty();
    if (!lens.imageDistanceAuto && last.thickness == 0.0 && !lastZoomed) {
        // As in pbrt's .dat and the patent-converted libraries: 0 means "at the paraxial image".
        lens.imageDistanceAuto = true;
        reporter.note(last.origin, "last thickness 0: read as 'auto', the sensor at the paraxial focus");
    }
    if (!lens.imageDistanceAuto && !(last.thickness > 0.0))
        throwInputError(last.origin, "the last thickness (distance to the sensor) must be positive, got " +
                                         text::roundTrip(last.thickness) + "; use 'auto' for the paraxial focus");
    for (std::size_t i = 0; i < lens.zoomGaps.size(); ++i)
        for (double g : lens.zoomGaps[i])
            if (i + 1 == surfaces.size() && !(g > 0.0))
                throwInputError(surfaces[i].origin, "every zoom value of the last thickness must be positive");

    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        const Surface& s = surfaces[i];
        if (s.semiAperture == 0.0 && !s.stop)
            reporter.note(s.origin, "surface " + std::to_string(i + 1) +
                                        " has semi-aperture 0 (not given): it is treated as unclipped");
        if (!s.rotationallySymmetric() && s.isAspheric())
            throwInputError(s.origin, std::string("surface ") + std::to_string(i + 1) + ": asph= on a " +
                                          toString(s.shape) + " surface is not supported (no anamorphic asphere)");
        if (!s.rotationallySymmetric())
            reporter.note(s.origin, std::string("surface ") + std::to_string(i + 1) + " is anamorphic (" +
                                        toString(s.shape) +
                                        "): first-order data are given per section (x-z and y-z); stages that "
                                        "need a rotationally symmetric lens will refuse it");
    }

    if (lens.imageDistanceAuto) {
        focusAtParaxialImage(lens);
        reporter.note(last.origin, "sensor distance 'auto': placed at the paraxial focus (d line), " +
                                       text::fixed(surfaces.back().thickness, 4) + " mm behind the last vertex");
    }

    bool clamped = false;
    const double r = workingStopSemiAperture(lens, &clamped);
    if (clamped)
        reporter.warning(surfaces[*stop].origin, "f_number " + text::roundTrip(*lens.fNumber) +
                                                     " needs a larger opening than the stop's semi-aperture " +
                                                     text::roundTrip(surfaces[*stop].semiAperture) +
                                                     " mm; clamping the aperture to the stop");
    else if (lens.fNumber && surfaces[*stop].semiAperture == 0.0)
        reporter.note(surfaces[*stop].origin, "stop semi-aperture set to " + text::fixed(r, 4) + " mm by f_number " +
                                                  text::roundTrip(*lens.fNumber));
}

} // namespace ff::optics
