// libFuzzer target for the explicit ghost list (`render --ghosts`, docs/fourier.md): ghosts or
// ff::Error, nothing else. Every ghost it returns has finite position, widths > 0 and flux >= 0.

#include "core/error.h"
#include "scene/scene.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        for (const ff::fourier::Ghost& g :
             ff::scene::parseGhostsJson(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz")) {
            if (!std::isfinite(g.x) || !std::isfinite(g.y)) std::abort();
            for (int c = 0; c < 3; ++c)
                if (!(g.widthX[c] > 0.0) || !(g.widthY[c] > 0.0) || !(g.flux[c] >= 0.0)) std::abort();
        }
    } catch (const ff::Error&) {
    }
    return 0;
}
