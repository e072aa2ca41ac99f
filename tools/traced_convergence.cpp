// The traced renderer's convergence for one lens and light: the default render against one with R
// times the refinement (trace::TracedFlareOptions::refinement), as a Markdown table row: relative L2
// per channel, flux difference per channel, rays and seconds of each. With --png PREFIX it also writes
// PREFIX-default.png, PREFIX-refined.png and PREFIX-unrefined.png (the starting grid drawn as it is),
// all at the refined render's exposure. Run by hand for docs/tracing.md:
//   build/release/tools/traced-convergence lenses/tessar-100mm-f3.5.lens --light 700,150 --size 960x540 --refine 4

#include "cli/trace_choices.h"
#include "core/error.h"
#include "image/image_output.h"
#include "image/metrics.h"
#include "scene/scene.h"
#include "trace/traced_flare.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>

using namespace ff;

namespace {

struct Run {
    scene::TracedScene scene;
    double seconds = 0.0;
};

Run render(const optics::Lens& lens, const ghosts::Light& light, trace::TracedFlareOptions o) {
    const auto t0 = std::chrono::steady_clock::now();
    Run r;
    r.scene = scene::renderTracedScene(lens, {light}, o);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

std::vector<float> channel(const fourier::FlareImage& img, int c) {
    return std::vector<float>(img.channel[c].begin(), img.channel[c].end());
}

} // namespace

int main(int argc, char** argv) {
    CLI::App app("Convergence of the traced renderer: default against R times the refinement");
    std::string lensFile, light = "0,0", size = "960x540", zoom, png;
    double R = 4.0;
    app.add_option("lens", lensFile)->required();
    app.add_option("--light", light, "X,Y pixels");
    app.add_option("--size", size, "WIDTHxHEIGHT");
    app.add_option("--zoom", zoom);
    app.add_option("--refine", R, "the refined render's factor");
    app.add_option("--png", png, "write PREFIX-default.png, -refined.png, -unrefined.png");
    CLI11_PARSE(app, argc, argv);
    try {
        NullReporter quiet;
        const optics::Lens lens = cli::loadTraceableLens(lensFile, zoom, quiet);
        int W = 0, H = 0;
        if (std::sscanf(size.c_str(), "%dx%d", &W, &H) != 2) throw Error(ErrorKind::Usage, "--size WIDTHxHEIGHT");
        const ghosts::Light l = scene::parseLight(light);
        trace::TracedFlareOptions o;
        const auto sensor = lens.sensorMm.value_or(std::make_pair(36.0, 24.0));
        o.frame = {W, H, sensor.first / W};
        const Run a = render(lens, l, o);
        o.refinement = R;
        const Run b = render(lens, l, o);
        std::string cells;
        double worst = 0.0;
        for (int c = 0; c < 3; ++c) {
            const image::ImageError e = image::compareImages(channel(a.scene.image, c), channel(b.scene.image, c));
            worst = std::max(worst, e.relativeL2);
            char buf[96];
            std::snprintf(buf, sizeof buf, " %.4f / %+.3f %% |", e.relativeL2, 100.0 * (e.fluxRatio - 1.0));
            cells += buf;
        }
        std::printf("| %s | %s |%s %.1f M / %.1f s | %.1f M / %.1f s |\n", lens.name.c_str(), light.c_str(),
                    cells.c_str(), static_cast<double>(a.scene.samples) / 1e6, a.seconds,
                    static_cast<double>(b.scene.samples) / 1e6, b.seconds);
        if (!png.empty()) {
            o.refinement = 1.0;
            o.adaptive = false;
            const Run u = render(lens, l, o);
            const std::vector<float> ref = b.scene.image.interleaved();
            const double ev = image::autoExposure(ref);
            for (const auto& [name, img] :
                 {std::pair{"default", &a.scene.image}, {"refined", &b.scene.image}, {"unrefined", &u.scene.image}})
                image::writePng(png + "-" + name + ".png", W, H, image::tonemapPreview(img->interleaved(), ev), {});
        }
        return worst <= 0.03 ? 0 : 3;
    } catch (const Error& e) {
        std::fprintf(stderr, "traced-convergence: %s\n", e.what());
        return 2;
    }
}
