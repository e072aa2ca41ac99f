#pragma once
// Rays through graded-index (GRIN) media (docs/grin.md; the media themselves: Medium::gradient).
//
// The index after a surface, in that surface's frame (r from the axis, z from its vertex, mm):
//
//     n(r, z, lambda) = n0(lambda) + sum_k a_k(lambda) r^(2k) + sum_k b_k(lambda) z^k,   k = 1, 2, ...
//
// n0 is the medium's own dispersion (Medium::index); each coefficient has its own, in Cauchy form
// through its value at the d line: c(lambda) = c_d + D (1 / L^2 - 1 / L_d^2), L in um.
//
// A ray obeys d/ds (n dr/ds) = grad n. With the optical direction v = n dr/ds (|v| = n) the state
// (r, v, L) follows, in the arc length s,
//
//     dr/ds = v / n(r),   dv/ds = grad n(r),   dL/ds = n(r)   (L: the optical path),
//
// integrated by the classical fourth-order Runge-Kutta scheme. The step is either fixed or chosen
// by step doubling: a step h and two of h / 2 differ by about 15 / 16 of the single step's error
// (the error falls as h^5 per step), and the step is kept where that estimate, over 15, stays under
// tolerance x h / 1 mm, so that the position error over a path of length l mm stays near
// tolerance x l. The path meets the next surface where z - vertexZ - sag(r) changes sign over a
// step; the crossing is found within the step by the Illinois variant of regula falsi on the
// step's length (each trial a fresh RK4 step from the step's start).

#include "optics/surface.h"

#include <glm/vec3.hpp>

#include <optional>
#include <vector>

namespace ff::optics {

/// A gradient at one wavelength, placed in the lens frame (the surface's vertex at vertexZ).
class GradientField {
  public:
    GradientField(double n0, const GradientIndex& g, double lambdaNm, double vertexZ);
    /// n at p (lens frame).
    double index(const glm::dvec3& p) const;
    /// grad n at p; *n receives n there.
    glm::dvec3 gradient(const glm::dvec3& p, double& n) const;

  private:
    double n0_, vertexZ_;
    std::vector<double> a_, b_;
};

struct GradientSettings {
    double step = 0.0;        ///< fixed step (mm) when > 0; otherwise chosen by `tolerance`
    double tolerance = 1e-8;  ///< error per mm of path, with step = 0: position (mm) + direction (rad) x 1 mm
    double initialStep = 0.0; ///< first trial step (mm) with step = 0; 0: the straight distance to the far vertex
    std::size_t maxSteps = 1000000;
};

/// Where a ray through a gradient meets the next surface.
struct GradientHit {
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0};   ///< the surface's unit normal there, +z oriented
    glm::dvec3 dir{0.0};      ///< the ray's unit direction arriving there
    double index = 1.0;       ///< n at the point
    double opticalPath = 0.0; ///< integral of n ds from the start, mm
    double length = 0.0;      ///< arc length, mm
    std::size_t steps = 0;    ///< RK4 steps taken (accepted ones)
    double maxRadius = 0.0;   ///< the largest distance from the axis along the path, mm
};

/// Why a ray through a gradient did not arrive.
enum class GradientLoss { None, Barrel, TurnedBack, Index, Steps };

/// Propagates the ray from `origin` along `dir` (on or before the space's first surface) through the
/// field until it meets surface `to` (vertex at toZ). Lost (nullopt) if the ray turns back across
/// surface `from` (vertex at fromZ) first, leaves the clear radius maxRadius (0: unlimited), meets
/// an index <= 0 or not finite, or runs out of steps; *loss, where given, says which.
std::optional<GradientHit> propagate(const GradientField& field, const glm::dvec3& origin, const glm::dvec3& dir,
                                     const Surface& from, double fromZ, const Surface& to, double toZ,
                                     double maxRadius = 0.0, const GradientSettings& settings = {},
                                     GradientLoss* loss = nullptr);

} // namespace ff::optics
