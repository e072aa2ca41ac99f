#include "diffraction/wavefront.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "optics/paraxial.h"
#include "trace/ghost_path.h"
#include "trace/pupil_sampling.h"
#include "trace/sequential_tracer.h"
#include "trace/traced_flare.h"

#include <glm/geometric.hpp>
#include <glm/mat2x2.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

namespace ff::diffraction {

namespace {

constexpr int kDegree = 10; // the fit's total degree

// T_0..T_kDegree at x (Chebyshev polynomials of the first kind).
void chebyshev(double x, double* t) {
    t[0] = 1.0;
    t[1] = x;
    for (int k = 2; k <= kDegree; ++k) t[k] = 2.0 * x * t[k - 1] - t[k - 2];
}

// Least squares by modified Gram-Schmidt, each column orthogonalised twice: A (rows x cols,
// column-major) = Q R, then x = R^-1 Q^T b for any b. Columns that vanish against the previous ones
// get a zero coefficient.
class LeastSquares {
  public:
    LeastSquares(std::vector<double> A, std::size_t rows, std::size_t cols)
        : Q_(std::move(A)), R_(cols * cols, 0.0), used_(cols, false), rows_(rows), cols_(cols) {
        for (std::size_t j = 0; j < cols; ++j) {
            double* qj = &Q_[j * rows];
            double before = 0.0;
            for (std::size_t r = 0; r < rows; ++r) before += qj[r] * qj[r];
            for (int pass = 0; pass < 2; ++pass)
                for (std::size_t k = 0; k < j; ++k) {
                    if (!used_[k]) continue;
                    const double* qk = &Q_[k * rows];
                    double d = 0.0;
                    for (std::size_t r = 0; r < rows; ++r) d += qk[r] * qj[r];
                    for (std::size_t r = 0; r < rows; ++r) qj[r] -= d * qk[r];
                    R_[k * cols + j] += d;
                }
            double norm = 0.0;
            for (std::size_t r = 0; r < rows; ++r) norm += qj[r] * qj[r];
            norm = std::sqrt(norm);
            if (!(norm > 1e-10 * std::sqrt(before))) continue;
            used_[j] = true;
            R_[j * cols + j] = norm;
            for (std::size_t r = 0; r < rows; ++r) qj[r] /= norm;
        }
    }
    std::vector<double> solve(const std::vector<double>& b) const {
        std::vector<double> y(cols_, 0.0), x(cols_, 0.0);
        for (std::size_t j = 0; j < cols_; ++j)
            if (used_[j])
                for (std::size_t r = 0; r < rows_; ++r) y[j] += Q_[j * rows_ + r] * b[r];
        for (std::size_t j = cols_; j-- > 0;) {
            if (!used_[j]) continue;
            double s = y[j];
            for (std::size_t k = j + 1; k < cols_; ++k) s -= R_[j * cols_ + k] * x[k];
            x[j] = s / R_[j * cols_ + j];
        }
        return x;
    }

  private:
    std::vector<double> Q_, R_;
    std::vector<bool> used_;
    std::size_t rows_, cols_;
};

// Functions of the pupil point fitted by products T_a(u / reach) T_b(v / reach), a + b <= kDegree,
// all on one basis: evaluate() fills every output at once.
class PupilFit {
  public:
    explicit PupilFit(double reach) : reach_(reach) {
        for (int a = 0; a <= kDegree; ++a)
            for (int b = 0; a + b <= kDegree; ++b) terms_.push_back({a, b});
    }
    std::size_t terms() const { return terms_.size(); }
    void basis(double u, double v, double* out) const {
        double a[kDegree + 1], b[kDegree + 1];
        chebyshev(u / reach_, a);
        chebyshev(v / reach_, b);
        for (std::size_t c = 0; c < terms_.size(); ++c) out[c] = a[terms_[c].first] * b[terms_[c].second];
    }
    void add(std::vector<double> coefficients) { outputs_.push_back(std::move(coefficients)); }
    std::size_t outputs() const { return outputs_.size(); }
    double first(double u, double v) const {
        double t[(kDegree + 1) * (kDegree + 2) / 2];
        basis(u, v, t);
        double w = 0.0;
        for (std::size_t c = 0; c < terms_.size(); ++c) w += outputs_[0][c] * t[c];
        return w;
    }
    void evaluate(double u, double v, double* out) const {
        double t[(kDegree + 1) * (kDegree + 2) / 2];
        basis(u, v, t);
        for (std::size_t o = 0; o < outputs_.size(); ++o) {
            double w = 0.0;
            for (std::size_t c = 0; c < terms_.size(); ++c) w += outputs_[o][c] * t[c];
            out[o] = w;
        }
    }

  private:
    double reach_;
    std::vector<std::pair<int, int>> terms_;
    std::vector<std::vector<double>> outputs_;
};

struct Traced {
    glm::dvec2 stop{0.0}; // the ray's point in the stop's plane, mm
    optics::Ray last;     // from the last surface's hit, the direction in image space
    double opl = 0.0;     // from the object-space plane through the first vertex, normal to the field
};

// The least-squares fits over the pupil (u, v in iris radii, within `reach`) of the OPD ws, then of
// each clipping surface's hit coordinate in hits.
std::shared_ptr<PupilFit> fitPupil(double reach, const std::vector<double>& us, const std::vector<double>& vs,
                                   const std::vector<double>& ws, const std::vector<std::vector<double>>& hits) {
    auto fit = std::make_shared<PupilFit>(reach);
    const std::size_t rows = ws.size(), cols = fit->terms();
    if (rows < 2 * cols)
        throw Error(ErrorKind::Input, "the wavefront: " + std::to_string(rows) + " traced rays are too few to fit it");
    std::vector<double> A(rows * cols), row(cols);
    for (std::size_t r = 0; r < rows; ++r) {
        fit->basis(us[r], vs[r], row.data());
        for (std::size_t c = 0; c < cols; ++c) A[c * rows + r] = row[c];
    }
    const LeastSquares solver(std::move(A), rows, cols);
    fit->add(solver.solve(ws));
    for (const auto& coordinate : hits) fit->add(solver.solve(coordinate));
    return fit;
}

// The chief ray by Newton's method on its point in the stop (the Jacobian by differences of step h,
// mm): sets p, its point in the entrance pupil's plane, and toPupil, the inverse of the Jacobian
// there (stop to pupil). irisRadius scales the tolerance; angleRad names the field in the error.
Traced chiefRay(const std::function<std::optional<Traced>(glm::dvec2)>& trace, double h, double irisRadius,
                double angleRad, glm::dvec2& p, glm::dmat2& toPupil) {
    std::optional<Traced> chief = trace(p);
    glm::dmat2 J(1.0);
    auto jacobian = [&](glm::dvec2 at, const Traced& t) -> bool {
        const auto dx = trace(at + glm::dvec2(h, 0.0)), dy = trace(at + glm::dvec2(0.0, h));
        if (!dx || !dy) return false;
        J = glm::dmat2((dx->stop - t.stop) / h, (dy->stop - t.stop) / h);
        return std::abs(glm::determinant(J)) > 0.0;
    };
    for (int it = 0; it < 50 && chief && glm::length(chief->stop) > 1e-10 * (1.0 + irisRadius); ++it) {
        if (!jacobian(p, *chief))
            chief.reset();
        else
            chief = trace(p -= glm::inverse(J) * chief->stop);
    }
    if (!chief || !(glm::length(chief->stop) <= 1e-6 * (1.0 + irisRadius)) || !jacobian(p, *chief))
        throw Error(ErrorKind::Input, "the wavefront at field " + text::fixed(angleRad * 180.0 / 3.141592653589793, 2) +
                                          " deg: no chief ray through the stop's centre");
    toPupil = glm::inverse(J);
    return *chief;
}

// The wavefront's statistics over the traced rays (OPD ws at pupil points us, vs) inside the iris
// that the lens lets through, with the fitted opd's residual and largest slope, into out.
void addStatistics(const std::vector<double>& ws, const std::vector<double>& us, const std::vector<double>& vs,
                   const std::vector<char>& inIris, const std::vector<char>& openRay,
                   const std::function<double(double, double)>& opd, TracedWavefront& out) {
    const std::size_t rows = ws.size();
    double mean = 0.0, lo = INFINITY, hi = -INFINITY, residual = 0.0, slope = 0.0;
    std::size_t n = 0, blocked = 0;
    const double e = 1e-5;
    for (std::size_t r = 0; r < rows; ++r) {
        if (!inIris[r]) continue;
        if (!openRay[r]) {
            ++blocked;
            continue;
        }
        const double fitted = opd(us[r], vs[r]);
        mean += ws[r];
        lo = std::min(lo, ws[r]);
        hi = std::max(hi, ws[r]);
        residual += (ws[r] - fitted) * (ws[r] - fitted);
        slope = std::max(slope, std::hypot(opd(us[r] + e, vs[r]) - opd(us[r] - e, vs[r]),
                                           opd(us[r], vs[r] + e) - opd(us[r], vs[r] - e)) /
                                    (2.0 * e));
        ++n;
    }
    if (n == 0)
        throw Error(ErrorKind::Input, "the wavefront: the lens blocks every ray through the iris at this field");
    mean /= static_cast<double>(n);
    double variance = 0.0;
    for (std::size_t r = 0; r < rows; ++r)
        if (inIris[r] && openRay[r]) variance += (ws[r] - mean) * (ws[r] - mean);
    out.rays = n;
    out.vignetted = static_cast<double>(blocked) / static_cast<double>(n + blocked);
    out.rmsMm = std::sqrt(variance / static_cast<double>(n));
    out.peakToValleyMm = hi - lo;
    out.fitResidualMm = std::sqrt(residual / static_cast<double>(n));
    out.pupil.maxSlopeMm = slope;
}

} // namespace

TracedWavefront tracedWavefront(const optics::Lens& lens, double angleRad, double azimuthRad, double lambdaNm,
                                double sensorZ, const glm::dvec2* referenceMm, int grid) {
    const trace::LensAtWavelength L(lens, lambdaNm, sensorZ, trace::LensAtWavelength::Films::Exact); // unweighted
    const trace::PupilFrame pupil = trace::pupilFrame(lens);
    const std::vector<trace::PathStep> steps = trace::pathSteps(lens, std::nullopt);
    const glm::dvec3 d = trace::fieldDirection({angleRad, azimuthRad}, pupil.eflSign);
    const double back = (pupil.z - pupil.startZ) / d.z;
    std::size_t stopStep = 0;
    std::vector<std::size_t> clipping; // the steps whose surface has a clear aperture (not the stop)
    for (std::size_t k = 0; k < steps.size(); ++k) {
        if (steps[k].surface == L.stop)
            stopStep = k;
        else if (L.clipRadius[steps[k].surface] > 0.0)
            clipping.push_back(k);
    }
    std::vector<double> margins(steps.size());
    std::vector<glm::dvec3> points(steps.size());

    // One ray through the entrance pupil's plane at p, every aperture open.
    auto trace = [&](glm::dvec2 p) -> std::optional<Traced> {
        const optics::Ray ray{glm::dvec3(p, pupil.z) - back * d, d};
        const trace::SequentialResult s =
            trace::traceSequential(L, steps, ray, trace::Weighting::None, margins.data(), points.data());
        if (s.status != optics::RayStatus::Ok) return std::nullopt;
        Traced t;
        t.stop = glm::dvec2(points[stopStep]);
        // From the plane through the pupil's centre normal to the ray, then along the traced path
        // (curved through a graded element).
        t.opl = L.nBefore[steps.front().surface] * glm::dot(points.front(), d) + s.opticalPath;
        t.last = {points.back(), s.ray.dir};
        return t;
    };

    // The chief ray: its point in the entrance pupil's plane, and the map from the stop back there.
    glm::dvec2 p(0.0);
    glm::dmat2 toPupil(1.0);
    const Traced chief = chiefRay(trace, 1e-4 * pupil.radius, L.iris.radius, angleRad, p, toPupil);

    // The reference sphere: centred on the chief ray's point on the sensor (or the point given),
    // through the chief ray's point in the paraxial exit pupil's plane (or its last hit, for a lens
    // telecentric in image space).
    const double nImage = L.nAfter[steps.back().surface];
    auto onPlane = [](const optics::Ray& r, double z) { return r.origin + ((z - r.origin.z) / r.dir.z) * r.dir; };
    const glm::dvec3 chiefImage = onPlane(chief.last, L.sensorZ);
    const glm::dvec3 image = referenceMm ? glm::dvec3(*referenceMm, L.sensorZ) : chiefImage;
    const optics::FirstOrder fo = optics::analyzeFirstOrder(lens, lambdaNm);
    const glm::dvec3 rim =
        std::isfinite(fo.exitPupilZ) ? onPlane(chief.last, L.vertexZ.back() + fo.exitPupilZ) : chief.last.origin;
    const double radius = glm::length(rim - image);
    // OPL to the sphere: the ray's point where it crosses the sphere before reaching its centre.
    auto toSphere = [&](const Traced& t) -> std::optional<double> {
        const glm::dvec3 o = t.last.origin - image;
        const double b = glm::dot(o, t.last.dir), c = glm::dot(o, o) - radius * radius, disc = b * b - c;
        if (!(disc >= 0.0)) return std::nullopt;
        return t.opl + nImage * (-b - std::sqrt(disc));
    };
    const std::optional<double> chiefOpl = toSphere(chief);
    if (!chiefOpl) throw Error(ErrorKind::Input, "the wavefront: the chief ray misses its own reference sphere");

    // Rays over the iris (its circumscribed circle, a little beyond), mapped through the chief
    // ray's Jacobian from the stop back to the entrance pupil; each placed where it actually crosses
    // the stop, with its points on the surfaces that have a clear aperture.
    const double reach = 1.02 * L.iris.circumradius / L.iris.radius;
    std::vector<double> us, vs, ws;
    std::vector<std::vector<double>> hits(2 * clipping.size());
    std::vector<char> openRay, inIris;
    std::size_t inside = 0;
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const glm::dvec2 s =
                reach * L.iris.radius * glm::dvec2(2.0 * (i + 0.5) / grid - 1.0, 2.0 * (j + 0.5) / grid - 1.0);
            if (glm::length(s) > reach * L.iris.radius) continue;
            inside += L.iris.contains(s.x, s.y);
            const std::optional<Traced> t = trace(p + toPupil * s);
            if (!t) continue;
            const std::optional<double> opl = toSphere(*t);
            if (!opl) continue;
            const glm::dvec2 uv = t->stop / L.iris.radius;
            if (glm::length(uv) > reach) continue;
            us.push_back(uv.x);
            vs.push_back(uv.y);
            ws.push_back(*opl - *chiefOpl);
            bool through = true;
            for (std::size_t c = 0; c < clipping.size(); ++c) {
                hits[2 * c].push_back(points[clipping[c]].x);
                hits[2 * c + 1].push_back(points[clipping[c]].y);
                through = through && margins[clipping[c]] >= 0.0;
            }
            openRay.push_back(through);
            inIris.push_back(L.iris.contains(t->stop.x, t->stop.y));
        }
    std::size_t insideTraced = 0;
    for (char c : inIris) insideTraced += c;
    if (inside == 0 || 2 * insideTraced < inside)
        throw Error(ErrorKind::Input, "the wavefront: only " + std::to_string(insideTraced) + " of " +
                                          std::to_string(inside) + " rays inside the iris reach the sensor");

    // The fits: W, then each clipping surface's hit point (x, y), all smooth over the pupil.
    const auto fit = fitPupil(reach, us, vs, ws, hits);
    std::vector<double> clipRadius;
    for (std::size_t k : clipping) clipRadius.push_back(L.clipRadius[steps[k].surface]);
    auto opd = [fit](double u, double v) { return fit->first(u, v); };
    auto open = [fit, clipRadius](double u, double v) {
        // Called for every pupil sample of every PSF: one buffer per thread, not one per call.
        thread_local std::vector<double> o;
        o.resize(fit->outputs());
        fit->evaluate(u, v, o.data());
        for (std::size_t c = 0; c < clipRadius.size(); ++c)
            if (std::hypot(o[1 + 2 * c], o[2 + 2 * c]) > clipRadius[c]) return false;
        return true;
    };

    TracedWavefront out;
    out.pupil.opd = opd;
    if (!clipping.empty()) out.pupil.open = open;
    out.imageMm = glm::dvec2(chiefImage);
    addStatistics(ws, us, vs, inIris, openRay, opd, out);
    return out;
}

std::function<PupilFunction(double)> tracedPupil(const optics::Lens& lens, double xMm, double yMm, double sensorZ) {
    const trace::LensAtWavelength L(lens, lines::d, sensorZ, trace::LensAtWavelength::Films::Exact); // geometry
    const trace::Field field = trace::fieldForSensorPoint(lens, L.sensorZ, xMm, yMm);
    const glm::dvec2 reference = tracedWavefront(lens, field.angleRad, field.azimuthRad, lines::d, L.sensorZ).imageMm;
    const optics::Lens* l = &lens;
    const double z = L.sensorZ;
    return [l, field, reference, z](double lambdaNm) {
        return tracedWavefront(*l, field.angleRad, field.azimuthRad, lambdaNm, z, &reference).pupil;
    };
}

} // namespace ff::diffraction
