#include "optics/medium.h"

#include "core/units.h"

#include <cmath>

namespace ff::optics {

double Dispersion::index(double lambdaNm) const {
    const double l = nmToUm(lambdaNm);
    switch (model) {
    case Model::Constant:
        return n0;
    case Model::Cauchy:
        return cauchyA + cauchyB / (l * l);
    case Model::Sellmeier: {
        const double l2 = l * l;
        double n2 = 1.0;
        for (int i = 0; i < 3; ++i) n2 += sellB[i] * l2 / (l2 - sellC[i]);
        return std::sqrt(n2);
    }
    }
    return n0;
}

Dispersion Dispersion::constant(double n) {
    Dispersion d;
    d.model = Model::Constant;
    d.n0 = n;
    return d;
}

Dispersion Dispersion::cauchyFromAbbe(double nd, double vd) {
    if (vd == 0.0) return constant(nd);
    const double lF = nmToUm(lines::F), lC = nmToUm(lines::C), ld = nmToUm(lines::d);
    Dispersion d;
    d.model = Model::Cauchy;
    d.cauchyB = (nd - 1.0) / (vd * (1.0 / (lF * lF) - 1.0 / (lC * lC)));
    d.cauchyA = nd - d.cauchyB / (ld * ld);
    d.n0 = nd;
    return d;
}

Dispersion Dispersion::sellmeier(const std::array<double, 3>& b, const std::array<double, 3>& cUm2) {
    Dispersion d;
    d.model = Model::Sellmeier;
    d.sellB = b;
    d.sellC = cUm2;
    d.n0 = d.index(lines::d);
    return d;
}

double GradientTerm::at(double lambdaNm) const {
    const double l = nmToUm(lambdaNm), ld = nmToUm(lines::d);
    return atD + dispersion * (1.0 / (l * l) - 1.0 / (ld * ld));
}

Medium Medium::air() {
    return Medium{};
}

Medium Medium::fromNdVd(double nd, double vd) {
    Medium m;
    m.nd = nd;
    m.vd = vd;
    m.dispersion = Dispersion::cauchyFromAbbe(nd, vd);
    return m;
}

double abbeNumber(const Dispersion& d) {
    const double nF = d.index(lines::F), nC = d.index(lines::C);
    if (nF == nC) return 0.0;
    return (d.index(lines::d) - 1.0) / (nF - nC);
}

} // namespace ff::optics
