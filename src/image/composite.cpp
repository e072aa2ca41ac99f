#include "image/composite.h"

#include "core/error.h"

#include <cmath>

namespace ff::image {

std::vector<float> composite(const std::vector<float>& plate, const std::vector<float>& flare) {
    if (plate.size() != flare.size()) throwRuntimeError("composite: the flare does not match the plate");
    std::vector<float> out(plate.size());
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = flare[i] == 0.0f || std::isnan(plate[i]) ? plate[i] : plate[i] + flare[i];
    return out;
}

} // namespace ff::image
