#pragma once
// Reflectance of an optical interface, bare or coated, by exact electromagnetic theory.
//
// Bare: unpolarised Fresnel R = (Rs + Rp) / 2 in the cosine form (no 0/0 at normal incidence),
//   rs = (n1 cos_i - n2 cos_t) / (n1 cos_i + n2 cos_t),  rp = (n2 cos_i - n1 cos_t) / (n2 cos_i + n1 cos_t).
// Coated: characteristic-matrix method for a stack of lossless layers j (index n_j, thickness d_j):
//   M_j = [[cos d_j, i sin d_j / eta_j], [i eta_j sin d_j, cos d_j]],  d_j = 2 pi n_j d_j cos th_j / lambda,
//   eta = n cos th (s) or n / cos th (p),  [B; C] = (prod M_j) [1; eta_sub],  r = (eta_0 B - C) / (eta_0 B + C).
// Angles come from Snell's law in complex form, so total internal reflection needs no special case
// (R = 1). Media and layers are lossless, so T = 1 - R. Wavelengths in nm.

#include "optics/coating_spec.h"

#include <vector>

namespace ff::optics {

struct FilmLayer {
    double n = 1.0;           ///< refractive index at the wavelength of interest
    double thicknessNm = 0.0; ///< physical thickness
};

/// Unpolarised reflectance of a bare interface from n1 into n2 at incidence cosine cosI (0..1].
double fresnelReflectance(double n1, double n2, double cosI);

/// Unpolarised reflectance of a layer stack between an incident medium n0 and a substrate nSub,
/// layers listed from the incident side. An empty stack gives fresnelReflectance.
double filmReflectance(double n0, const std::vector<FilmLayer>& layers, double nSub, double cosI, double lambdaNm);

/// filmReflectance of one stack at one wavelength from one side, tabulated over the incidence for a
/// tracer's inner loop. Where every angle in the stack is real (cos_i above u* = sqrt(1 - n_min^2 /
/// n_0^2), n_min the least index of the layers and the substrate; u* = 0 when n_min >= n_0), R is an
/// analytic function of s = sqrt(cos_i^2 - u*^2) — the square-root branch point at the critical angle
/// is taken out, every layer's cosine is smooth in s — and is interpolated by cubic Hermite pieces
/// over 1024 equal intervals of s, from the exact values and slopes at their ends (error O(h^4):
/// within 2.2e-9 absolute for the bundled lenses' coatings, tests/optics/test_thin_film.cpp). Below the
/// table's first interval (at and beyond the critical angle) it calls filmReflectance.
class FilmReflectanceTable {
  public:
    FilmReflectanceTable() = default;
    FilmReflectanceTable(double n0, std::vector<FilmLayer> layers, double nSub, double lambdaNm);
    double operator()(double cosI) const;

  private:
    static constexpr int kIntervals = 1024;
    double n0_ = 1.0, nSub_ = 1.0, lambdaNm_ = 550.0;
    std::vector<FilmLayer> layers_;
    double uStar2_ = 0.0, sLo_ = 0.0, sStep_ = 1.0; // u*^2, the table's first knot in s, the interval
    std::vector<double> knots_;                     // per knot: R, then h dR/ds
};

/// The layers of a coating spec at lambdaNm: indices from the coating-material catalogue, physical
/// thickness d = waves * lambda0 / n(lambda0). Listed from the outer (air) side to the substrate.
std::vector<FilmLayer> filmLayers(const CoatingSpec& spec, double lambdaNm);

/// Reflectance of a coated interface for light going from medium n1 into n2. The coating sits on the
/// higher-index side (the glass), so its layers are met in spec order when light comes from the
/// lower-index side, and in reverse order otherwise.
double coatedReflectance(const CoatingSpec& spec, double n1, double n2, double cosI, double lambdaNm);

} // namespace ff::optics
