// The traced wavefront against geometry derived here: a sensor moved back by delta adds the defocus
// -delta (1 - cos U') of a converging spherical wave to a ray leaving at U', the wavefront on the axis
// is symmetric about it, and the PSF made from an off-axis wavefront has the centroid of the
// geometric spot (the Fraunhofer PSF's centroid is the mean of the rays' transverse aberrations).

#include "diffraction/wavefront.h"
#include "optics/lens_loader.h"
#include "optics/paraxial.h"
#include "trace/ghost_path.h"
#include "trace/pupil_sampling.h"
#include "trace/sequential_tracer.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace ff::diffraction {
namespace {

optics::Lens focused(const char* name) {
    optics::Lens lens = optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/" + name);
    optics::focusAtParaxialImage(lens);
    return lens;
}

// A ray of the axial field at height y in the entrance pupil, every aperture open: its point in the
// stop's plane and its direction in image space.
std::pair<glm::dvec3, glm::dvec3> axialRay(const optics::Lens& lens, double lambdaNm, double y) {
    const trace::LensAtWavelength L(lens, lambdaNm);
    const auto steps = trace::pathSteps(lens, std::nullopt);
    const trace::PupilFrame pupil = trace::pupilFrame(lens);
    std::vector<double> margins(steps.size());
    std::vector<glm::dvec3> points(steps.size());
    const trace::SequentialResult s = trace::traceSequential(L, steps, {{0.0, y, pupil.startZ}, {0.0, 0.0, 1.0}},
                                                             trace::Weighting::None, margins.data(), points.data());
    EXPECT_EQ(s.status, optics::RayStatus::Ok);
    std::size_t stop = 0;
    for (std::size_t k = 0; k < steps.size(); ++k)
        if (steps[k].surface == L.stop) stop = k;
    return {points[stop], s.ray.dir};
}

TEST(Wavefront, MovingTheSensorAddsTheDefocusOfASphericalWave) {
    const optics::Lens lens = focused("double-gauss-50mm-f2.lens");
    const double lambda = 587.56, delta = 0.05;
    const double sensor = optics::analyzeFirstOrder(lens, lambda).totalTrack;
    const double a = trace::LensAtWavelength(lens, lambda).iris.radius;
    const TracedWavefront at = tracedWavefront(lens, 0.0, 0.0, lambda, sensor);
    const TracedWavefront back = tracedWavefront(lens, 0.0, 0.0, lambda, sensor + delta);
    EXPECT_LT(at.fitResidualMm, 1e-3 * lambda * 1e-6);
    const double y0 = 0.5 * optics::analyzeFirstOrder(lens, lambda).entrancePupilDiameter;
    for (double share : {0.5, 0.9}) {
        const auto [stop, dir] = axialRay(lens, lambda, share * y0);
        const double u = stop.x / a, v = stop.y / a;
        const double added =
            (back.pupil.opd(u, v) - back.pupil.opd(0.0, 0.0)) - (at.pupil.opd(u, v) - at.pupil.opd(0.0, 0.0));
        // The wave converges to F, the reference sphere (radius R) is centred delta behind it: a ray
        // at U' through F meets it at s = R - delta cos U' before F, the chief ray at R - delta, so
        // its path to the sphere is delta (cos U' - 1) longer than the chief's (air behind the lens).
        const double expected = -delta * (1.0 - dir.z);
        EXPECT_NEAR(added / expected, 1.0, 0.01) << share;
    }
}

TEST(Wavefront, IsSymmetricAboutTheAxisOnTheAxis) {
    const optics::Lens lens = focused("double-gauss-50mm-f2.lens");
    const double lambda = 486.13; // the F line: the lens's spherical aberration and focus shift differ from d's
    const TracedWavefront w = tracedWavefront(lens, 0.0, 0.0, lambda);
    ASSERT_GT(w.rmsMm, 0.05 * lambda * 1e-6); // a real aberration to test against
    const double wave = lambda * 1e-6;
    for (double r : {0.3, 0.6, 0.95})
        for (double phi : {0.4, 1.3, 2.2, 3.9, 5.1})
            EXPECT_NEAR(w.pupil.opd(r * std::cos(phi), r * std::sin(phi)), w.pupil.opd(r, 0.0), 2e-3 * wave)
                << r << " " << phi;
    EXPECT_NEAR(w.imageMm.x, 0.0, 1e-9);
    EXPECT_NEAR(w.imageMm.y, 0.0, 1e-9);
}

TEST(Wavefront, ThePsfsCentroidIsTheGeometricSpots) {
    const optics::Lens lens = focused("double-gauss-50mm-f2.lens");
    const double lambda = 587.56, angle = 12.0 * std::numbers::pi / 180.0, azimuth = 0.7;
    const TracedWavefront w = tracedWavefront(lens, angle, azimuth, lambda);

    // The geometric spot: rays over the entrance pupil that the lens lets through, on the sensor.
    const trace::LensAtWavelength L(lens, lambda);
    const auto steps = trace::pathSteps(lens, std::nullopt);
    const trace::PupilFrame pupil = trace::pupilFrame(lens);
    const trace::Bundle b = trace::gridBundle(pupil, {angle, azimuth}, 600, 0.0, 0.0, 3.0 * pupil.radius, false);
    glm::dvec2 sum(0.0);
    std::size_t n = 0;
    for (const optics::Ray& ray : b.rays) {
        const trace::SequentialResult s = trace::traceSequential(L, steps, ray, trace::Weighting::None);
        if (s.status != optics::RayStatus::Ok) continue;
        sum += glm::dvec2(s.ray.origin);
        ++n;
    }
    ASSERT_GT(n, 10000u);
    const glm::dvec2 geometric = sum / double(n) - w.imageMm;

    const Aperture aperture = apertureOf(lens);
    const double spacing = lambda * 1e-6 * aperture.fNumber / 4.0;
    const SampledPsf p = sampledPsf(aperture, lambda, spacing, 1024, w.pupil.opd, w.pupil.open);
    glm::dvec2 centroid(0.0);
    for (int r = 0; r < p.size; ++r)
        for (int c = 0; c < p.size; ++c) {
            const double v = p.value[static_cast<std::size_t>(r) * p.size + c];
            centroid += v * spacing * glm::dvec2(c - p.size / 2, r - p.size / 2);
        }
    ASSERT_GT(glm::length(geometric), 4.0 * spacing); // a real offset to test against
    EXPECT_LT(glm::length(centroid - geometric), 0.05 * glm::length(geometric));
}

} // namespace
} // namespace ff::diffraction
