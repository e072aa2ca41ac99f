#pragma once
// A bundled lens set up for tracing at 550 nm on its own sensor plane, shared by the bundle-moment and
// pupil-region tests.

#include "optics/lens_loader.h"
#include "trace/bundle_moments.h"
#include "trace/flare_raster.h"
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

    /// A path's moments on an n x n grid over region r: plain, or with its edges resolved on
    /// subdivisions x subdivisions sub-grids.
    trace::BundleMoments grid(const std::vector<trace::PathStep>& steps, const trace::Field& f,
                              const trace::PupilRegion& r, int n, int subdivisions) const {
        const trace::Bundle b = trace::regionBundle(pupil, f, r, n);
        std::vector<trace::RayResult> c(b.rays.size());
        tracer.trace(L, steps, b.rays, c);
        if (subdivisions == 0) return trace::measureBundle(b, c, 1.0, kMaxRadius);
        const trace::Bundle corners = trace::cornerBundle(pupil, f, b);
        std::vector<trace::RayResult> k(corners.rays.size());
        tracer.trace(L, steps, corners.rays, k);
        return trace::measureBundleResolved(tracer, L, steps, pupil, f, b, c, k, subdivisions, 1.0, kMaxRadius);
    }
};

} // namespace ff::test
