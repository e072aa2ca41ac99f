#include "optics/lens.h"

#include "core/error.h"
#include "core/text.h"

#include <cmath>

namespace ff::optics {

std::size_t Lens::stopIndex() const {
    for (std::size_t i = 0; i < surfaces.size(); ++i)
        if (surfaces[i].stop) return i;
    throw Error(ErrorKind::Input, SourceLocation{file}, "the lens has no aperture stop");
}

const Medium& Lens::mediumBefore(std::size_t i) const {
    static const Medium air = Medium::air();
    return i == 0 ? air : surfaces[i - 1].medium;
}

double Lens::vertexZ(std::size_t i) const {
    double z = 0.0;
    for (std::size_t j = 0; j < i; ++j) z += surfaces[j].thickness;
    return z;
}

double Lens::sensorZ() const {
    return vertexZ(surfaces.size());
}

CoatingSpec Lens::coatingOf(std::size_t i) const {
    const Surface& s = surfaces[i];
    if (s.coating) return *s.coating;
    // AR coatings sit on glass-air surfaces; a cemented (glass-glass) or air-air surface stays bare
    // whatever the column says (FlareSim-family files mark cemented rows as coated).
    if (s.coatingLayers <= 0 || mediumBefore(i).isAir() == s.medium.isAir()) return CoatingSpec::none();
    if (defaultCoating) return *defaultCoating;
    return s.coatingLayers == 1 ? CoatingSpec::mgf2() : CoatingSpec::broadband();
}

bool Lens::rotationallySymmetric() const {
    for (const auto& s : surfaces)
        if (!s.rotationallySymmetric()) return false;
    return true;
}

std::vector<std::size_t> Lens::reflectingInterfaces(double lambdaNm) const {
    std::vector<std::size_t> r;
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        const double n1 = mediumBefore(i).index(lambdaNm), n2 = surfaces[i].medium.index(lambdaNm);
        if (std::abs(n1 - n2) > 1e-9) r.push_back(i);
    }
    return r;
}

} // namespace ff::optics
