#include "cli/dirt_choices.h"

#include "core/error.h"
#include "core/text.h"
#include "image/plate.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>
#include <optional>

namespace ff::cli {

void DirtOptions::addTo(CLI::App& cmd) {
    cmd.add_option("--aperture-mask", apertureMask,
                   "Dirt on the front element from an image of its transmittance (1 clear, 0 opaque; luminance; "
                   "its centred square spans the iris's circumscribed circle), multiplying the iris: its "
                   "diffraction joins the starburst");
    cmd.add_option("--dirt", dirt,
                   "Procedural dust and scratches on the front element, SEED[,DENSITY] (density 1: about 80 specks "
                   "and 3 scratches; the same seed gives the same dirt), multiplying the iris");
}

std::shared_ptr<const diffraction::PupilMask> DirtOptions::mask(const std::string& checker) const {
    diffraction::PupilMask m;
    if (!apertureMask.empty()) {
        image::PlateLimits limits;
        limits.maxPixels = 8192ull * 8192ull;
        limits.maxChannels = 64;
        limits.checker = checker;
        limits.cpuSeconds = image::plateCheckSeconds();
        const image::Plate p = image::readPlate(apertureMask, limits);
        m = diffraction::maskFromImage(p.pixels, p.width, p.height, static_cast<int>(p.channels.size()), p.r,
                                       p.r == p.g ? -1 : p.g, p.r == p.b ? -1 : p.b, apertureMask);
    }
    if (!dirt.empty()) {
        const std::size_t comma = dirt.find(',');
        const std::string seedText = dirt.substr(0, comma);
        char* end = nullptr;
        errno = 0;
        const unsigned long long seed = std::strtoull(seedText.c_str(), &end, 10);
        if (seedText.empty() || seedText[0] == '-' || *end != '\0' || errno == ERANGE)
            throw Error(ErrorKind::Usage,
                        "--dirt takes SEED[,DENSITY] with SEED a whole number >= 0, got " + text::quoted(dirt));
        double density = 1.0;
        if (comma != std::string::npos) {
            const std::string d = dirt.substr(comma + 1);
            const std::optional<double> given = text::parseNumber(d);
            if (!given || !(*given > 0.0 && *given <= 100.0))
                throw Error(ErrorKind::Usage,
                            "--dirt's DENSITY must be a number above 0 and at most 100, got " + text::quoted(d));
            density = *given;
        }
        m = diffraction::combine(m, diffraction::proceduralDirt(seed, density));
    }
    if (m.empty()) return nullptr;
    return std::make_shared<const diffraction::PupilMask>(std::move(m));
}

} // namespace ff::cli
