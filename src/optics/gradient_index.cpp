#include "optics/gradient_index.h"

#include "core/units.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace ff::optics {

GradientField::GradientField(double n0, const GradientIndex& g, double lambdaNm, double vertexZ)
    : n0_(n0), vertexZ_(vertexZ) {
    for (const GradientTerm& t : g.radial) a_.push_back(t.at(lambdaNm));
    for (const GradientTerm& t : g.axial) b_.push_back(t.at(lambdaNm));
}

double GradientField::index(const glm::dvec3& p) const {
    double n = 0.0;
    gradient(p, n);
    return n;
}

glm::dvec3 GradientField::gradient(const glm::dvec3& p, double& n) const {
    // Radial part in s = r^2: P(s) = sum a_k s^k, dn/dx = 2 x P'(s); axial part Q(z), dn/dz = Q'(z).
    const double s = p.x * p.x + p.y * p.y, z = p.z - vertexZ_;
    double P = 0.0, dP = 0.0, Q = 0.0, dQ = 0.0;
    for (std::size_t k = a_.size(); k-- > 0;) {
        dP = dP * s + P;
        P = P * s + a_[k];
    }
    // Now P = sum a_k s^(k-1) and dP = sum (k-1) a_k s^(k-2): the polynomial over s and its slope
    // are s P and P + s dP.
    const double radial = s * P, radialSlope = P + s * dP;
    for (std::size_t k = b_.size(); k-- > 0;) {
        dQ = dQ * z + Q;
        Q = Q * z + b_[k];
    }
    const double axial = z * Q, axialSlope = Q + z * dQ;
    n = n0_ + radial + axial;
    return {2.0 * p.x * radialSlope, 2.0 * p.y * radialSlope, axialSlope};
}

namespace {

struct State {
    glm::dvec3 p{0.0}, v{0.0};
    double L = 0.0; ///< optical path
};

struct Slope {
    glm::dvec3 dp{0.0}, dv{0.0};
    double dL = 0.0;
};

// False where the index is not positive and finite.
bool derivative(const GradientField& f, const State& y, Slope& d) {
    double n = 0.0;
    const glm::dvec3 g = f.gradient(y.p, n);
    if (!(n > 0.0) || !std::isfinite(n)) return false;
    d = {y.v / n, g, n};
    return true;
}

State advance(const State& y, const Slope& d, double h) {
    return {y.p + h * d.dp, y.v + h * d.dv, y.L + h * d.dL};
}

// One classical RK4 step of length h.
std::optional<State> rk4(const GradientField& f, const State& y, double h, const Slope* k1At = nullptr) {
    Slope k1, k2, k3, k4;
    if (k1At)
        k1 = *k1At;
    else if (!derivative(f, y, k1))
        return std::nullopt;
    if (!derivative(f, advance(y, k1, h / 2), k2) || !derivative(f, advance(y, k2, h / 2), k3) ||
        !derivative(f, advance(y, k3, h), k4))
        return std::nullopt;
    State out;
    out.p = y.p + h / 6.0 * (k1.dp + 2.0 * k2.dp + 2.0 * k3.dp + k4.dp);
    out.v = y.v + h / 6.0 * (k1.dv + 2.0 * k2.dv + 2.0 * k3.dv + k4.dv);
    out.L = y.L + h / 6.0 * (k1.dL + 2.0 * k2.dL + 2.0 * k3.dL + k4.dL);
    if (!std::isfinite(out.p.x + out.p.y + out.p.z + out.v.x + out.v.y + out.v.z + out.L)) return std::nullopt;
    return out;
}

// Which side of a surface p lies on: z - vertexZ - sag(r) (mm); NaN where the sag is undefined.
double side(const Surface& s, double vertexZ, const glm::dvec3& p) {
    const auto sag = s.sag(std::sqrt(p.x * p.x + p.y * p.y));
    return sag ? p.z - vertexZ - *sag : std::nan("");
}

// A step's path as the cubic Hermite curve p(t), t in [0, 1], through its ends with tangents h v / |v|
// (dr/ds = v / n and |v| = n on the ray).
struct Hermite {
    glm::dvec3 p0, m0, p1, m1;
    Hermite(const State& a, const State& b, double h)
        : p0(a.p), m0(h * glm::normalize(a.v)), p1(b.p), m1(h * glm::normalize(b.v)) {}
    glm::dvec3 at(double t) const {
        const double t2 = t * t, t3 = t2 * t;
        return (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * p1 + (t3 - t2) * m1;
    }
    // The largest distance from the axis over [0, end], sampled at 8 points and the ends.
    double maxRadius(double end) const {
        double r2 = 0.0;
        for (int k = 0; k <= 8; ++k) {
            const glm::dvec3 q = at(end * k / 8.0);
            r2 = std::max(r2, q.x * q.x + q.y * q.y);
        }
        return std::sqrt(r2);
    }
};

// Where the curve (inside the space at t = 0, past surface `to` at t = 1) crosses it: the Illinois
// method on side() along the curve, to 1e-10 of the step or 1e-12 mm off the surface (the caller's
// move along the tangent onto the surface takes the rest).
double crossing(const Hermite& curve, const Surface& to, double toZ, double sign) {
    double a = 0.0, fa = side(to, toZ, curve.p0) * sign, b = 1.0, fb = side(to, toZ, curve.p1) * sign;
    for (int i = 0; i < 100 && std::abs(b - a) > 1e-10 && std::abs(fb) > 1e-12; ++i) {
        const double c = fa == fb ? (a + b) / 2 : b - fb * (b - a) / (fb - fa);
        const double fc = side(to, toZ, curve.at(c)) * sign;
        if (std::isnan(fc)) return b;
        if ((fc < 0.0) == (fb < 0.0)) {
            fa /= 2.0;
        } else {
            a = b;
            fa = fb;
        }
        b = c;
        fb = fc;
    }
    return std::clamp(b, 0.0, 1.0);
}

} // namespace

std::optional<GradientHit> propagate(const GradientField& field, const glm::dvec3& origin, const glm::dvec3& dir,
                                     const Surface& from, double fromZ, const Surface& to, double toZ, double maxRadius,
                                     const GradientSettings& settings, GradientLoss* loss) {
    const auto lost = [&](GradientLoss why) -> std::optional<GradientHit> {
        if (loss) *loss = why;
        return std::nullopt;
    };
    if (loss) *loss = GradientLoss::None;
    if (toZ == fromZ) return lost(GradientLoss::TurnedBack);
    // The space lies on this side of `from` and on the other side of `to`.
    const double sign = toZ > fromZ ? 1.0 : -1.0;
    const bool fixed = settings.step > 0.0;
    // A step of the scheme in use: one RK4 step, or two of half the length (the step doubling's
    // more accurate result).
    const auto step = [&](const State& y, double h) -> std::optional<State> {
        if (fixed) return rk4(field, y, h);
        const auto half = rk4(field, y, h / 2);
        return half ? rk4(field, *half, h / 2) : std::nullopt;
    };
    State y;
    y.p = origin;
    const double n0 = field.index(origin);
    if (!(n0 > 0.0) || !std::isfinite(n0)) return lost(GradientLoss::Index);
    y.v = glm::normalize(dir) * n0;
    // The first trial step: the straight distance to the far vertex plane (the whole element when
    // the gradient allows it), unless given.
    const glm::dvec3 unit = glm::normalize(dir);
    const double straight = std::abs(toZ - origin.z) / std::max(std::abs(unit.z), 0.05);
    double h =
        fixed ? settings.step : (settings.initialStep > 0.0 ? settings.initialStep : std::clamp(straight, 1e-3, 1e3));
    double length = 0.0;
    std::size_t steps = 0;                           // accepted
    double reached = std::hypot(origin.x, origin.y); // the largest radius along the accepted path
    for (std::size_t tries = 0; tries < settings.maxSteps; ++tries) {
        std::optional<State> next;
        double hNext = h;
        if (fixed) {
            next = rk4(field, y, h);
        } else {
            Slope k1; // shared by the single step and the first half step
            if (!derivative(field, y, k1)) return lost(GradientLoss::Index);
            const auto single = rk4(field, y, h, &k1);
            const auto half = rk4(field, y, h / 2, &k1);
            if (half) next = rk4(field, *half, h / 2);
            if (!single || !next) {
                // A trial step that reaches an index <= 0: shorter ones may not.
                if (h < 1e-6) return lost(GradientLoss::Index);
                h /= 4.0;
                continue;
            }
            // The estimate: position (mm) and direction (rad, read over 1 mm) together.
            const double error =
                (glm::length(single->p - next->p) + glm::length(single->v - next->v) / glm::length(next->v)) / 15.0;
            const double allowed = settings.tolerance * h;
            // The next step's factor 0.9 (allowed / error)^(1/5), at most 4 (reached from a ratio of 1734).
            const double factor = error * 1734.0 < allowed ? 4.0 : 0.9 * std::pow(allowed / error, 0.2);
            if (error > allowed && h > 1e-9) {
                h *= std::max(0.2, factor);
                continue;
            }
            hNext = h * std::clamp(factor, 0.2, 4.0);
            // Local extrapolation: the two half steps' error is (double - single) / 15 to leading
            // order; removing it leaves a fifth-order step (the estimate above then bounds its error).
            next->p += (next->p - single->p) / 15.0;
            next->v += (next->v - single->v) / 15.0;
            next->L += (next->L - single->L) / 15.0;
        }
        if (!next) return lost(GradientLoss::Index);
        // The path over the step as the cubic Hermite curve through its ends and their tangents: where
        // it crosses the surface and how far from the axis it goes, without evaluating the field.
        const Hermite curve(y, *next, h);
        const double past = side(to, toZ, next->p) * sign;
        if (std::isnan(past)) return lost(GradientLoss::Barrel); // beyond the surface's conic
        const double end = past >= 0.0 ? crossing(curve, to, toZ, sign) : 1.0;
        const double widest = curve.maxRadius(end);
        if (maxRadius > 0.0 && widest > maxRadius) return lost(GradientLoss::Barrel);
        reached = std::max(reached, widest);
        if (past >= 0.0) {
            // The crossing lies within this step, at the curve's root: one step there, then along
            // the tangent onto the surface (the step and the curve differ by far less than the
            // tolerance; the straight move's error is of the square of that difference).
            const double c = end * h;
            auto at = step(y, c);
            if (!at) return lost(GradientLoss::Index);
            const auto normal0 = to.normal({at->p.x, at->p.y, at->p.z - toZ});
            const glm::dvec3 t = glm::normalize(at->v);
            const double f = side(to, toZ, at->p), slope = normal0 ? glm::dot(*normal0, t) / normal0->z : 0.0;
            if (std::isnan(f) || !(std::abs(slope) > 1e-6)) return lost(GradientLoss::Barrel);
            const double delta = -f / slope;
            at->p += delta * t;
            at->L += delta * glm::length(at->v);
            GradientHit hit;
            hit.point = at->p;
            const auto normal = to.normal({at->p.x, at->p.y, at->p.z - toZ});
            if (!normal) return lost(GradientLoss::Barrel);
            hit.normal = *normal;
            hit.dir = t;
            hit.index = field.index(at->p);
            hit.opticalPath = at->L;
            hit.length = length + c + delta;
            hit.steps = steps + 1;
            hit.maxRadius = std::max(reached, std::hypot(at->p.x, at->p.y));
            return hit;
        }
        if (side(from, fromZ, next->p) * sign < -1e-9) return lost(GradientLoss::TurnedBack);
        y = *next;
        length += h;
        h = hNext;
        ++steps;
    }
    return lost(GradientLoss::Steps);
}

} // namespace ff::optics
