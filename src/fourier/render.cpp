#include "fourier/render.h"

#include "core/stopwatch.h"
#include "fourier/bessel.h"
#include "fourier/direct.h"

namespace ff::fourier {

std::string FourierRender::describe() const {
    return coarse ? plan.describe() + "; coarse level: " + coarse->describe() : plan.describe();
}

namespace {

// Accumulates and evaluates one level into `image` (adding), then draws its direct ghosts.
void renderLevel(const std::vector<Ghost>& ghosts, const Plan& plan, const FourierSettings& settings, FlareImage& image,
                 StageSeconds& seconds, Clock::time_point& t) {
    if (settings.backend) {
        settings.backend->addLevel(ghosts, plan, settings, seconds);
        t = Clock::now();
        return;
    }
    const Coefficients z = accumulate(ghosts, plan, settings);
    seconds.accumulate += lap(t);
    evaluate(z, plan.evaluation, image, Write::Add);
    seconds.evaluate += lap(t);
    std::vector<std::size_t> direct;
    for (std::size_t k = 0; k < ghosts.size(); ++k)
        if (plan.route[k] == Route::Direct) direct.push_back(k);
    drawDirect(ghosts, direct, image);
    seconds.direct += lap(t);
}

} // namespace

FourierRender renderFourier(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings) {
    if (settings.basis == Basis::Bessel) return renderBessel(ghosts, width, height, settings);
    FourierRender r;
    r.image = FlareImage(width, height);
    auto t = Clock::now();
    r.plan = choosePlan(ghosts, width, height, settings);
    r.seconds.plan = lap(t);
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
        r.seconds.plan += lap(t);
        renderLevel(wide, *r.coarse, coarse, r.image, r.seconds, t);
    }
    if (settings.backend) {
        settings.backend->finish(r.image);
        r.seconds.evaluate += lap(t); // the read-back
    }
    return r;
}

FlareImage renderDirect(const std::vector<Ghost>& ghosts, int width, int height) {
    FlareImage image(width, height);
    drawDirect(ghosts, image);
    return image;
}

} // namespace ff::fourier
