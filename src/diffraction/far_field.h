#pragma once
// The PSF beyond the transform's reach: the iris's edge diffraction in closed form (docs/diffraction.md,
// "The far field").
//
// The transform of a polygon's indicator is, by the divergence theorem, a sum over its edges (length
// L, unit outward normal n, tangent t, midpoint m; nu != 0, s and nu in units of the pupil's
// diameter D):
//
//     P^(nu) = i / (2 pi |nu|^2) sum_e (nu.n_e) L_e sinc(pi L_e nu.t_e) exp(-2 pi i nu.m_e).
//
// Far from the light the edges' cross terms oscillate faster than a pixel and the spectrum (their
// phases turn by 2 pi nu.(m_e - m_f)), so the pixels see the sum of the edges' own intensities. With
// the pixel's coordinates X (pixels) = beta nu, beta = lambda N / pitch, rho = X.n and d = X.t, each
// edge gives the pixel the share of the flux
//
//     L^2 / (4 pi^2 A) x rho^2 / (rho^2 + d^2)^2 x Int_pixel sinc^2(pi L d / beta) dX,
//
// A = the pupil's area (units of D^2): a spike along +-n falling as 1 / rho^2, whose width
// (beta / L, under a pixel at f/8 on a 1080p frame) is integrated over the pixel's footprint exactly
// (Line::profile). A round iris gives the Airy pattern's mean far field, beta / (pi^3 r^3) per pixel.

#include "diffraction/aperture.h"

#include <array>
#include <functional>
#include <vector>

namespace ff::diffraction {

/// One wavelength's or an RGB mixture's far field, in pixels (+x right, +y down, offsets from the
/// light's pixel).
struct FarField {
    /// The edges whose normals lie along one line (a polygon with an even number of blades pairs
    /// them): a spike along +-(nx, ny).
    struct Line {
        double nx = 0.0, ny = 0.0; ///< unit direction of the spike
        double step = 0.0;         ///< pixels between the profile's samples
        int half = 0;              ///< the profile holds d = (i - half) step, i = 0 .. 2 half
        /// Per channel: L^2 / (4 pi^2 A) x Int_pixel sinc^2(pi L d / beta), summed over the line's
        /// edges and the wavelengths (weighted): the share times rho^2 (rho >> d). It ends smoothly
        /// (cos^2 from half its reach to 0 at it): the edges' faint halo between the spikes (under
        /// 1e-3 of the spike's flux) ends there without an edge, the same everywhere.
        std::array<std::vector<double>, 3> profile;
        double reach() const { return half * step; }
    };
    std::vector<Line> lines;
    std::array<double, 3> airy{}; ///< round iris: the share is airy / r^3

    bool empty() const { return lines.empty() && airy[0] == 0.0 && airy[1] == 0.0 && airy[2] == 0.0; }
    /// Share of the light's flux on the pixel at offset (dx, dy), channel c; 0 at the light's pixel.
    double at(int c, double dx, double dy) const;
    /// Calls add(dx, dy, share) for every pixel within |dx| <= rx, |dy| <= ry outside the square
    /// |dx|, |dy| <= inner where the far field is not zero: each line's band (its profile's reach
    /// across it, the line's own share there; the shares of several lines at a pixel add up to at()),
    /// the whole plane for a round iris.
    void forEach(int c, int rx, int ry, int inner, const std::function<void(int dx, int dy, double share)>& add) const;
};

/// The far field of `aperture` on pixels of pitchMm, over the wavelengths with per-channel weights
/// (weights[i][c] for wavelength i).
FarField farField(const Aperture& aperture, double pitchMm, const std::vector<double>& wavelengthsNm,
                  const std::vector<std::array<double, 3>>& weights);

} // namespace ff::diffraction
