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

std::string FourierRender::describe() const {
    return coarse ? plan.describe() + "; coarse level: " + coarse->describe() : plan.describe();
}

namespace {

// Accumulates and evaluates one level into `image` (adding), then draws its direct ghosts.
void renderLevel(const std::vector<Ghost>& ghosts, const Plan& plan, const FourierSettings& settings, FlareImage& image,
                 StageSeconds& seconds, std::chrono::steady_clock::time_point& t) {
    if (settings.backend) {
        settings.backend->addLevel(ghosts, plan, settings, seconds);
        t = std::chrono::steady_clock::now();
        return;
    }
    const Coefficients z = accumulate(ghosts, plan, settings);
    seconds.accumulate += since(t);
    evaluate(z, plan.evaluation, image, Write::Add);
    seconds.evaluate += since(t);
    std::vector<std::size_t> direct;
    for (std::size_t k = 0; k < ghosts.size(); ++k)
        if (plan.route[k] == Route::Direct) direct.push_back(k);
    drawDirect(ghosts, direct, image);
    seconds.direct += since(t);
}

} // namespace

FourierRender renderFourier(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings) {
    if (settings.basis == Basis::Bessel) return renderBessel(ghosts, width, height, settings);
    FourierRender r;
    r.image = FlareImage(width, height);
    auto t = std::chrono::steady_clock::now();
    r.plan = choosePlan(ghosts, width, height, settings);
    r.seconds.plan = since(t);
    if (settings.backend) settings.backend->begin(width, height);
    renderLevel(ghosts, r.plan, settings, r.image, r.seconds, t);
    if (r.plan.wide > 0) {
        std::vector<Ghost> wide;
        for (std::size_t k = 0; k < ghosts.size(); ++k)
            if (r.plan.route[k] == Route::Wide) wide.push_back(ghosts[k]);
        FourierSettings coarse = settings;
        coarse.periodCap = 32.0;
        coarse.fixedN = coarse.fixedM = 0;
        coarse.fixedPeriodX = coarse.fixedPeriodY = 0.0;
        coarse.hybrid = true;
        r.coarse = choosePlan(wide, width, height, coarse);
        // Wider still: drawn directly.
        for (Route& route : r.coarse->route)
            if (route == Route::Wide) route = Route::Direct;
        r.coarse->direct += r.coarse->wide;
        r.coarse->wide = 0;
        r.seconds.plan += since(t);
        renderLevel(wide, *r.coarse, coarse, r.image, r.seconds, t);
    }
    if (settings.backend) {
        settings.backend->finish(r.image);
        r.seconds.evaluate += since(t); // the read-back
    }
    return r;
}

FlareImage renderDirect(const std::vector<Ghost>& ghosts, int width, int height) {
    FlareImage image(width, height);
    drawDirect(ghosts, image);
    return image;
}

} // namespace ff::fourier
