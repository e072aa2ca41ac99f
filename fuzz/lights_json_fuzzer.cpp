// libFuzzer target for the lights file (`--lights`, docs/simulate.md): lights or ff::Error with
// file:line:column, nothing else. Every light it returns has finite coordinates and flux >= 0.

#include "core/error.h"
#include "scene/scene.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        for (const ff::ghosts::Light& l :
             ff::scene::parseLightsJson(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz")) {
            if (!std::isfinite(l.xPx) || !std::isfinite(l.yPx)) std::abort();
            for (double f : l.flux)
                if (!(f >= 0.0) || !std::isfinite(f)) std::abort();
        }
    } catch (const ff::Error&) {
    }
    return 0;
}
