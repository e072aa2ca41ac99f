#include "fourier/render.h"

#include "fourier/bessel.h"
#include "fourier/direct.h"

#include <chrono>

namespace ff::fourier {

namespace {

double since(std::chrono::steady_clock::time_point& t) {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
}

} // namespace

FourierRender renderFourier(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings) {
    if (settings.basis == Basis::Bessel) return renderBessel(ghosts, width, height, settings);
    FourierRender r;
    auto t = std::chrono::steady_clock::now();
    r.plan = choosePlan(ghosts, width, height, settings);
    r.seconds.plan = since(t);
    const Coefficients z = accumulate(ghosts, r.plan, settings);
    r.seconds.accumulate = since(t);
    r.image = FlareImage(width, height);
    evaluate(z, r.plan.evaluation, r.image);
    r.seconds.evaluate = since(t);
    std::vector<std::size_t> direct;
    for (std::size_t k = 0; k < ghosts.size(); ++k)
        if (r.plan.route[k] == Route::Direct) direct.push_back(k);
    drawDirect(ghosts, direct, r.image);
    r.seconds.direct = since(t);
    return r;
}

FlareImage renderDirect(const std::vector<Ghost>& ghosts, int width, int height) {
    FlareImage image(width, height);
    drawDirect(ghosts, image);
    return image;
}

} // namespace ff::fourier
