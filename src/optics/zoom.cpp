#include "optics/zoom.h"

#include "core/error.h"
#include "core/text.h"
#include "optics/paraxial.h"

namespace ff::optics {

Lens atZoom(const Lens& lens, std::size_t k) {
    if (k >= lens.zoomCount())
        throw Error(ErrorKind::Usage, "zoom position " + std::to_string(k + 1) + " does not exist; the lens has " +
                                          std::to_string(lens.zoomCount()) + " position(s)");
    Lens out = lens;
    out.activeZoom = k;
    for (std::size_t i = 0; i < out.surfaces.size() && i < out.zoomGaps.size(); ++i)
        if (!out.zoomGaps[i].empty()) out.surfaces[i].thickness = out.zoomGaps[i][k];
    if (out.imageDistanceAuto) focusAtParaxialImage(out);
    return out;
}

std::size_t findZoomPosition(const Lens& lens, const std::string& labelOrIndex) {
    for (std::size_t k = 0; k < lens.zoomLabels.size(); ++k)
        if (lens.zoomLabels[k] == labelOrIndex) return k;
    if (auto idx = text::parseInt(labelOrIndex); idx && *idx >= 1 && static_cast<std::size_t>(*idx) <= lens.zoomCount())
        return static_cast<std::size_t>(*idx - 1);
    throw Error(ErrorKind::Usage, "no zoom position " + text::quoted(labelOrIndex) + "; valid positions: " +
                                      (lens.isZoom() ? text::join(lens.zoomLabels) : std::string("1 (a prime lens)")));
}

} // namespace ff::optics
