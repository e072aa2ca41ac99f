#pragma once
// What anti-reflection coating a surface carries, as written in lens files:
//   none | mgf2 [LAMBDA0] | stack(MATERIAL:WAVES, ...) [LAMBDA0]
// LAMBDA0 is the design wavelength in nm (default 550); WAVES is the layer's optical thickness in
// waves at LAMBDA0 (0.25 = quarter wave). In a surface row the parts are joined by '@' with no spaces:
// coating=mgf2@550, coating=stack(MgF2:0.25,ZrO2:0.5,Al2O3:0.25)@550. The physics (exact thin-film
// reflectance) lives with the tracer; this is only the description.

#include "core/error.h"

#include <string>
#include <string_view>
#include <vector>

namespace ff::optics {

struct CoatingLayer {
    std::string material; ///< name in the coating-material catalogue (MgF2, ZrO2, Al2O3, ...)
    double waves = 0.25;  ///< optical thickness n*d in waves at the design wavelength
    bool operator==(const CoatingLayer&) const = default;
};

struct CoatingSpec {
    /// Layers from the outer medium towards the substrate; empty = bare surface.
    std::vector<CoatingLayer> layers;
    double lambda0Nm = 550.0;

    bool bare() const { return layers.empty(); }
    bool operator==(const CoatingSpec&) const = default;

    static CoatingSpec none() { return {}; }
    /// Single quarter-wave MgF2 layer at lambda0Nm (the default AR coating).
    static CoatingSpec mgf2(double lambda0Nm = 550.0);
    /// MgF2 l/4 / ZrO2 l/2 / Al2O3 l/4: a typical broadband multi-layer stack (optics.md).
    static CoatingSpec broadband(double lambda0Nm = 550.0);

    /// Canonical text: "none", "mgf2 550", "stack(MgF2:0.25,ZrO2:0.5,Al2O3:0.25) 550".
    std::string str() const;
    /// The same with '@' instead of the space, for use inside a surface row token.
    std::string token() const;
};

/// Parses a coating spec (either the spaced or the '@' form). `where` locates the text's first
/// character; errors point at the offending part and list the valid forms.
CoatingSpec parseCoatingSpec(std::string_view text, const SourceLocation& where);

} // namespace ff::optics
