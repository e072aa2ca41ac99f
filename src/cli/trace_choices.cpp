#include "cli/trace_choices.h"

#include "core/error.h"
#include "optics/lens_loader.h"

namespace ff::cli {

optics::Lens loadTraceableLens(const std::string& file, const std::string& zoom, Reporter& reporter) {
    optics::Lens lens = optics::loadLens(file, &reporter);
    if (!zoom.empty()) lens = optics::atZoom(lens, optics::findZoomPosition(lens, zoom));
    if (!lens.rotationallySymmetric())
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    "the lens has anamorphic surfaces; the ghost tracer needs a rotationally symmetric lens");
    return lens;
}

trace::Sampling samplingFrom(const std::string& s) {
    return s == "paraxial-grid" ? trace::Sampling::ParaxialGrid : trace::Sampling::Reaim;
}

trace::SensorPlane sensorFrom(const std::string& s) {
    return s == "paraxial" ? trace::SensorPlane::Paraxial : trace::SensorPlane::File;
}

trace::CoatingChoice coatingFrom(const std::string& s) {
    if (s == "none") return trace::CoatingChoice::None;
    if (s == "mgf2") return trace::CoatingChoice::MgF2;
    return trace::CoatingChoice::File;
}

} // namespace ff::cli
