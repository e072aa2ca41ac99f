#include "optics/lens_loader.h"
#include "trace/traced_flare.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "test_support.h"
#include "uniform_ellipse.h"

using namespace ff;
using namespace ff::trace;

namespace {

double channelSum(const TracedFlare& f, int c) {
    double s = 0.0;
    for (std::size_t p = c; p < f.rgb.size(); p += 3) s += f.rgb[p];
    return s;
}

} // namespace

// An uncoated glass plate (n = 1.5, non-dispersive) behind a 5 mm stop, lit on axis by a collimated
// beam. Its one ghost reflects off the back face, then the front face, at normal incidence, so every
// ray keeps the weight R^2 (1 - R)^2 with R = ((n - 1) / (n + 1))^2 = 0.04 and the direct image's
// rays (1 - R)^2: the ghost carries R^2 = 1.6e-3 of the direct flux, spread uniformly over a disc of
// the stop's radius, 5 mm, centred on the axis. (The back face has a 1e6 mm radius, as the tracer
// needs a lens with power: its mirror power 2 n / R images the beam at 1 + 65 mm x 3e-6 = 1.0002,
// 0.04 % in irradiance, far inside the tolerances.) Pixel (i, j) of a 960 x 540 frame over 36 mm
// holds R^2 x (its area inside the disc) / (pi 5^2), the area found here by 64 x 64 point sampling
// of each pixel the rim crosses.
TEST(TracedFlare, AGlassPlateGhostIsAUniformDiscOfKnownIrradiance) {
    test::TempDir dir;
    test::writeFile(dir / "plate.lens", "name: plate\nsensor: 36x24\nsurfaces:\n"
                                        "  stop 10 1.0 0 5 0\n"
                                        "  0 5 1.5 0 12 0\n"
                                        "  1e6 50 1.0 0 12 0\n");
    const optics::Lens lens = optics::loadLens(dir / "plate.lens");
    TracedFlareOptions o;
    const int W = 960, H = 540;
    const double pitch = 36.0 / W;
    o.frame = {W, H, pitch};
    const TracedFlare f = renderTracedFlare(lens, o);
    ASSERT_EQ(f.ghostCount, 1u);
    const double R = 0.04, r = 5.0;
    const std::vector<double> expected = test::uniformEllipse(o.frame, r, r, R * R);
    for (int c = 0; c < 3; ++c) {
        const test::Agreement a = test::agreement(f.rgb, c, expected);
        EXPECT_GE(a.lowest, 0.0) << "channel " << c;
        EXPECT_LE(a.relativeL2, 0.01) << "channel " << c;
        EXPECT_NEAR(a.sum, R * R, 1e-4 * R * R) << "channel " << c;
    }
}

// The traced flare of a real lens is the same to the byte on one thread and on two; the image holds
// exactly the drawn ghosts' flux (in the frame) and no negative pixel.
TEST(TracedFlare, SameBytesForOneAndTwoThreadsAndNoNegativePixels) {
    const optics::Lens lens = optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens"));
    TracedFlareOptions o;
    o.frame = {320, 180, 36.0 / 320};
    o.field = {12.0 * std::numbers::pi / 180.0, 0.4};
    auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        return renderTracedFlare(lens, o);
    };
    const TracedFlare one = run(1), two = run(2);
    ASSERT_EQ(one.rgb.size(), two.rgb.size());
    EXPECT_TRUE(std::equal(one.rgb.begin(), one.rgb.end(), two.rgb.begin()));
    EXPECT_GE(*std::min_element(two.rgb.begin(), two.rgb.end()), 0.0f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(channelSum(two, c), two.stats[c].deposited, 1e-5 * two.stats[c].deposited);
}
