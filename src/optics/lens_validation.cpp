#include "optics/lens_validation.h"

#include "core/text.h"
#include "optics/paraxial.h"

#include <cmath>

namespace ff::optics {

void validateLens(Lens& lens, const SourceLocation& section, Reporter& reporter) {
    auto& surfaces = lens.surfaces;
    if (surfaces.empty()) throwInputError(section, "the lens has no surfaces");

    std::optional<std::size_t> stop;
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        if (!surfaces[i].stop) continue;
        if (stop)
            throwInputError(surfaces[i].origin, "a second aperture stop (surface " + std::to_string(i + 1) +
                                                    "); surface " + std::to_string(*stop + 1) + " is already the stop");
        stop = i;
    }
    if (!stop)
        throwInputError(section, "no aperture stop: mark one surface as the stop (a 'stop' row for a flat stop, "
                                 "or the word 'stop' after the columns of a curved surface)");

    const Surface& last = surfaces.back();
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
            reporter.note(s.origin, "surface " + std::to_string(i + 1) + " has semi-aperture 0 (not given): it is treated as unclipped");
        if (!s.rotationallySymmetric())
            reporter.note(s.origin, std::string("surface ") + std::to_string(i + 1) + " is anamorphic (" + toString(s.shape) +
                                        "): first-order data use the radius of the y-z section; stages that need a "
                                        "rotationally symmetric lens will refuse it");
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
