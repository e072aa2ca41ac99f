#pragma once
// Optical media and their dispersion: n(lambda) by Sellmeier (named catalogue glasses), by Cauchy
// fitted to (nd, Vd) (patent data without glass names), or constant (air, Vd = 0). Wavelengths in nm.

#include "core/error.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace ff::optics {

struct Dispersion {
    enum class Model { Constant, Cauchy, Sellmeier };

    Model model = Model::Constant;
    double n0 = 1.0;                     ///< Constant: the index
    double cauchyA = 0.0, cauchyB = 0.0; ///< Cauchy: n = A + B / L^2, L in um
    std::array<double, 3> sellB{};       ///< Sellmeier: n^2 - 1 = sum B_i L^2 / (L^2 - C_i)
    std::array<double, 3> sellC{};       ///< in um^2

    /// Refractive index at lambdaNm (nm).
    double index(double lambdaNm) const;

    static Dispersion constant(double n);
    /// Cauchy through nd at the d line with Abbe number vd (optics.md): B = (nd - 1) /
    /// (vd (1/LF^2 - 1/LC^2)), A = nd - B / Ld^2. vd = 0 gives a constant index.
    static Dispersion cauchyFromAbbe(double nd, double vd);
    static Dispersion sellmeier(const std::array<double, 3>& b, const std::array<double, 3>& cUm2);
};

/// One coefficient of a graded index and its dispersion, in Cauchy form through the d line:
/// c(lambda) = atD + dispersion (1 / L^2 - 1 / L_d^2), L in um.
struct GradientTerm {
    double atD = 0.0;        ///< at the d line (587.56 nm); mm^-k for the term in r^k or z^k
    double dispersion = 0.0; ///< the change per 1 / L^2 (L in um): the same units times um^2
    double at(double lambdaNm) const;
};

/// A graded index added to a medium's own n0(lambda): n = n0 + sum a_k r^(2k) + sum b_k z^k, r
/// from the axis and z from the vertex of the surface the medium follows, mm (optics/gradient_index.h).
struct GradientIndex {
    std::vector<GradientTerm> radial; ///< a_1, a_2, ...: of r^2, r^4, ...
    std::vector<GradientTerm> axial;  ///< b_1, b_2, ...: of z, z^2, ...
    SourceLocation origin;            ///< where it was given (for messages)
};

/// The medium that follows a surface (towards the sensor).
struct Medium {
    std::string glass; ///< catalogue name, or empty for media given by (nd, Vd)
    double nd = 1.0;   ///< index at the d line (derived from the model for catalogue glasses)
    double vd = 0.0;   ///< Abbe number (0 = non-dispersive)
    Dispersion dispersion;
    std::optional<GradientIndex> gradient; ///< a graded index; none: homogeneous

    /// The index at lambdaNm (on the axis at the vertex, n0, for a graded medium).
    double index(double lambdaNm) const { return dispersion.index(lambdaNm); }
    /// Air: constant index 1 and no glass name.
    bool isAir() const {
        return glass.empty() && dispersion.model == Dispersion::Model::Constant && n0() == 1.0 && !gradient;
    }
    double n0() const { return dispersion.n0; }

    static Medium air();
    static Medium fromNdVd(double nd, double vd);
};

/// Abbe number (nd - 1) / (nF - nC) of a dispersion model; 0 for a non-dispersive one.
double abbeNumber(const Dispersion& d);

} // namespace ff::optics
