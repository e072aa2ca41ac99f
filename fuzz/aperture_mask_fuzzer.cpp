// libFuzzer target for the aperture masks (`--aperture-mask FILE`, docs/diffraction.md "Dirt"): the
// bytes as an image file, read as the mask is, turned into a transmittance and multiplied with
// procedural dirt. A mask is a transmittance in [0, 1] on a square raster, or ff::Error.

#include "core/error.h"
#include "diffraction/pupil_mask.h"
#include "image/plate.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz_image.h"

using namespace ff;

namespace {

void checkMask(const diffraction::PupilMask& m) {
    if (m.size < 1 || m.transmittance.size() != static_cast<std::size_t>(m.size) * static_cast<std::size_t>(m.size))
        std::abort();
    for (float t : m.transmittance)
        if (!(t >= 0.0f && t <= 1.0f)) std::abort();
    const double centre = m.at(0.0, 0.0), corner = m.at(1.5, -1.5);
    if (!(centre >= 0.0 && centre <= 1.0) || corner != 1.0) std::abort();
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    fuzz::oneThread();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string& path = fuzz::asFile(data, size, "ff-fuzz-mask");
    try {
        const image::Plate p = image::readPlate(path, fuzz::smallLimits());
        const diffraction::PupilMask m =
            diffraction::maskFromImage(p.pixels, p.width, p.height, static_cast<int>(p.channels.size()), p.r,
                                       p.r == p.g ? -1 : p.g, p.r == p.b ? -1 : p.b, path);
        checkMask(m);
        checkMask(diffraction::combine(m, diffraction::proceduralDirt(size, 1.0 + static_cast<double>(size % 7), 64)));
    } catch (const Error&) {
    }
    return 0;
}
