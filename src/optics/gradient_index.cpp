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
std::optional<State> rk4(const GradientField& f, const State& y, double h) {
    Slope k1, k2, k3, k4;
    if (!derivative(f, y, k1) || !derivative(f, advance(y, k1, h / 2), k2) ||
        !derivative(f, advance(y, k2, h / 2), k3) || !derivative(f, advance(y, k3, h), k4))
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
    const auto sag = s.sag(std::hypot(p.x, p.y));
    return sag ? p.z - vertexZ - *sag : std::nan("");
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
    double h = fixed ? settings.step : settings.initialStep, length = 0.0;
    std::size_t steps = 0;                           // accepted
    double reached = std::hypot(origin.x, origin.y); // the largest radius at an accepted node
    for (std::size_t tries = 0; tries < settings.maxSteps; ++tries) {
        std::optional<State> next;
        double hNext = h;
        if (fixed) {
            next = rk4(field, y, h);
        } else {
            const auto single = rk4(field, y, h);
            next = step(y, h);
            if (!single || !next) return lost(GradientLoss::Index);
            const double error = glm::length(single->p - next->p) / 15.0, allowed = settings.tolerance * h;
            const double factor = error > 0.0 ? 0.9 * std::pow(allowed / error, 0.2) : 4.0;
            if (error > allowed && h > 1e-9) {
                h *= std::max(0.2, factor);
                continue;
            }
            hNext = h * std::clamp(factor, 0.2, 4.0);
        }
        if (!next) return lost(GradientLoss::Index);
        const double past = side(to, toZ, next->p) * sign;
        if (std::isnan(past)) return lost(GradientLoss::Barrel); // beyond the surface's conic
        if (past >= 0.0) {
            // The crossing lies within this step: the Illinois method on the step's length.
            double a = 0.0, fa = side(to, toZ, y.p) * sign, b = h, fb = past;
            State at = *next;
            for (int i = 0; i < 200 && std::abs(fb) > 1e-13 && std::abs(b - a) > 1e-15; ++i) {
                const double c = fa == fb ? (a + b) / 2 : b - fb * (b - a) / (fb - fa);
                const auto yc = step(y, c);
                if (!yc) return lost(GradientLoss::Index);
                const double fc = side(to, toZ, yc->p) * sign;
                if (std::isnan(fc)) return lost(GradientLoss::Barrel);
                if ((fc < 0.0) == (fb < 0.0)) {
                    fa /= 2.0;
                } else {
                    a = b;
                    fa = fb;
                }
                b = c;
                fb = fc;
                at = *yc;
            }
            GradientHit hit;
            hit.point = at.p;
            const auto normal = to.normal({at.p.x, at.p.y, at.p.z - toZ});
            if (!normal) return lost(GradientLoss::Barrel);
            hit.normal = *normal;
            hit.dir = glm::normalize(at.v);
            hit.index = field.index(at.p);
            hit.opticalPath = at.L;
            hit.length = length + b;
            hit.steps = steps + 1;
            hit.maxRadius = std::max(reached, std::hypot(at.p.x, at.p.y));
            return hit;
        }
        if (side(from, fromZ, next->p) * sign < -1e-9) return lost(GradientLoss::TurnedBack);
        if (maxRadius > 0.0 && std::hypot(next->p.x, next->p.y) > maxRadius) return lost(GradientLoss::Barrel);
        y = *next;
        reached = std::max(reached, std::hypot(y.p.x, y.p.y));
        length += h;
        h = hNext;
        ++steps;
    }
    return lost(GradientLoss::Steps);
}

} // namespace ff::optics
