#pragma once
// A bundled lens set up for tracing at 550 nm on its own sensor plane, shared by the pupil-region tests.

#include "optics/lens_loader.h"
#include "trace/ghost_analysis.h"

#include "test_support.h"

namespace ff::test {

// Light is counted within twice the half-diagonal of a 36 x 24 mm sensor, as the ghost table does.
constexpr double kMaxRadius = 43.27;

struct LensBench {
    optics::Lens lens;
    double sensorZ;
    trace::PupilFrame pupil;
    trace::LensAtWavelength L;
    trace::EmbreeTracer tracer;

    explicit LensBench(const char* name)
        : lens(optics::loadLens(lensPath(name))), sensorZ(trace::sensorPlaneZ(lens, trace::SensorPlane::File)),
          pupil(trace::pupilFrame(lens)), L(lens, 550.0, sensorZ), tracer(L) {}
};

} // namespace ff::test
