// libFuzzer target for the plate reader's own checks (docs/reliability.md): the bytes as an image
// file, read in this process as the checker process reads it (its header checks: sizes, channels,
// deep data, windows; luminance-chroma; the values), then written as simulate writes it (every
// channel kept, a layer added) and read back. A reader may only return a plate or throw ff::Error.
//
// The image library is not instrumented and crashes or hangs on some damaged files; the CLI runs
// this read in a separate, time-limited process for that reason. A crash inside the library found
// here is triaged through that guard (`fourierflare simulate` must exit 2, in bounded time), not
// fixed here: run with -fork=1 -ignore_crashes=1 -ignore_timeouts=1 to go on past them.

#include "core/error.h"
#include "image/plate.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz_image.h"

using namespace ff;

namespace {

void checkPlate(const image::Plate& p) {
    const auto n = static_cast<int>(p.channels.size());
    if (p.width < 1 || p.height < 1 || n < 1 || p.pixels.size() != p.pixelCount() * p.channels.size()) std::abort();
    for (int c : {p.r, p.g, p.b})
        if (c < 0 || c >= n) std::abort();
    if (p.a >= n) std::abort();
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    fuzz::oneThread();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string& in = fuzz::asFile(data, size, "ff-fuzz-plate");
    image::Plate p;
    try {
        p = image::readPlate(in, fuzz::smallLimits());
    } catch (const Error&) {
        return 0;
    }
    checkPlate(p);
    // What simulate writes: every channel of the plate, then a layer; it must read back as a plate
    // with the same channels first.
    const std::vector<float> flare(p.pixelCount() * 3, 0.5f);
    const std::string& out = fuzz::scratchFile("ff-fuzz-plate-out");
    try {
        image::writeSimulatedExr(out, p, {{"flare", &flare}}, {}, (size & 1) != 0);
    } catch (const Error&) {
        return 0; // e.g. a channel name the EXR writer refuses: a precise error is a valid outcome
    }
    image::PlateLimits limits = fuzz::smallLimits();
    limits.maxChannels += 3;
    const image::Plate q = image::readPlate(out, limits);
    checkPlate(q);
    if (q.width != p.width || q.height != p.height || q.channels.size() != p.channels.size() + 3) std::abort();
    for (std::size_t c = 0; c < p.channels.size(); ++c)
        if (q.channels[c] != p.channels[c]) std::abort();
    return 0;
}
