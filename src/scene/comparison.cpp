#include "scene/comparison.h"

#include "core/error.h"
#include "core/file_io.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "ff/version.h"
#include "fourier/backend.h"
#include "fourier/render.h"
#include "ghosts/shaped_cache.h"
#include "image/image_output.h"
#include "image/metrics.h"
#include "scene/light_diffraction.h"
#include "scene/scene.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ff::scene {

namespace {

nlohmann::json toJson(const image::ImageError& e) {
    auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    return {{"relativeL2", finite(e.relativeL2)},
            {"psnrDb", finite(e.psnrDb)},
            {"maxAbs", e.maxAbs},
            {"maxRelative", e.maxRelative},
            {"fluxRatio", e.fluxRatio}};
}

std::string row(const std::string& what, const image::ImageError& e) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "| %s | %.3e | %.1f | %.3e | %.4f |\n", what.c_str(), e.relativeL2, e.psnrDb,
                  e.maxRelative, e.fluxRatio);
    return buf;
}

// Log-log plot of relative L2 against N, one polyline per series, as a small standalone SVG.
std::string errorPlot(const std::vector<int>& ns,
                      const std::vector<std::pair<std::string, std::vector<double>>>& series, double budget) {
    const double W = 640, H = 400, left = 70, right = 150, top = 20, bottom = 50;
    double lo = budget, hi = budget;
    for (const auto& s : series)
        for (double v : s.second)
            if (v > 0 && std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    const double ly0 = std::floor(std::log10(lo)), ly1 = std::ceil(std::log10(hi) + 1e-9);
    const double lx0 = std::log2(ns.front()), lx1 = std::max(lx0 + 1, std::log2(ns.back()));
    auto X = [&](double n) { return left + (std::log2(n) - lx0) / (lx1 - lx0) * (W - left - right); };
    auto Y = [&](double v) { return top + (ly1 - std::log10(v)) / (ly1 - ly0) * (H - top - bottom); };
    std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"400\" "
                      "font-family=\"sans-serif\" font-size=\"12\">\n"
                      "<rect width=\"640\" height=\"400\" fill=\"white\"/>\n";
    for (double e = ly0; e <= ly1; ++e)
        svg += "<line x1=\"" + text::fixed(left, 1) + "\" x2=\"" + text::fixed(W - right, 1) + "\" y1=\"" +
               text::fixed(Y(std::pow(10, e)), 1) + "\" y2=\"" + text::fixed(Y(std::pow(10, e)), 1) +
               "\" stroke=\"#ddd\"/><text x=\"" + text::fixed(left - 8, 1) + "\" y=\"" +
               text::fixed(Y(std::pow(10, e)) + 4, 1) + "\" text-anchor=\"end\">1e" +
               std::to_string(static_cast<int>(e)) + "</text>\n";
    for (int n : ns)
        svg += "<text x=\"" + text::fixed(X(n), 1) + "\" y=\"" + text::fixed(H - bottom + 18, 1) +
               "\" text-anchor=\"middle\">" + std::to_string(n) + "</text>\n";
    svg += "<text x=\"" + text::fixed(0.5 * (left + W - right), 1) + "\" y=\"" + text::fixed(H - 10, 1) +
           "\" text-anchor=\"middle\">N (terms along x)</text>\n";
    svg += "<text x=\"16\" y=\"" + text::fixed(0.5 * H, 1) + "\" transform=\"rotate(-90 16 " + text::fixed(0.5 * H, 1) +
           ")\" text-anchor=\"middle\">relative L2 error</text>\n";
    svg += "<line x1=\"" + text::fixed(left, 1) + "\" x2=\"" + text::fixed(W - right, 1) + "\" y1=\"" +
           text::fixed(Y(budget), 1) + "\" y2=\"" + text::fixed(Y(budget), 1) +
           "\" stroke=\"#888\" stroke-dasharray=\"4 3\"/><text x=\"" + text::fixed(W - right + 6, 1) + "\" y=\"" +
           text::fixed(Y(budget) + 4, 1) + "\">budget</text>\n";
    const char* colours[] = {"#d62728", "#1f77b4", "#ff7f0e", "#2ca02c"};
    for (std::size_t s = 0; s < series.size(); ++s) {
        std::string pts;
        for (std::size_t i = 0; i < ns.size(); ++i)
            if (series[s].second[i] > 0 && std::isfinite(series[s].second[i]))
                pts += text::fixed(X(ns[i]), 1) + "," + text::fixed(Y(series[s].second[i]), 1) + " ";
        const char* colour = colours[s % 4];
        svg += std::string("<polyline fill=\"none\" stroke=\"") + colour + "\" stroke-width=\"2\" points=\"" + pts +
               "\"/>\n";
        svg += "<text x=\"" + text::fixed(W - right + 6, 1) + "\" y=\"" + text::fixed(top + 16 + 16.0 * double(s), 1) +
               "\" fill=\"" + colour + "\">" + series[s].first + "</text>\n";
    }
    return svg + "</svg>\n";
}

// The lights' diffraction (docs/diffraction.md): the aberration-free PSF's, and with --diffraction
// traced the one with the lens's traced wavefront at each light's field, compared with it. The
// diffraction is the same for every ghost model, so it is shown apart from them.
std::string compareDiffraction(const ComparisonSettings& s, const optics::Lens& lens,
                               const trace::TracedFlareOptions& to, const std::filesystem::path& dir,
                               const image::Metadata& meta, nlohmann::json& report) {
    const std::vector<ghosts::Light>& lights = s.lights;
    const int W = to.frame.width, H = to.frame.height;
    std::string md =
        "## Diffraction\n\nThe lights through the lens's point-spread function (the same for every ghost model; "
        "the model: docs/diffraction.md):\n\n| PSF | flux in the frame / the lights' | seconds |\n|---|---|---|\n";
    double lightsFlux = 0.0;
    for (const auto& l : lights) lightsFlux += l.flux[0] + l.flux[1] + l.flux[2];
    std::vector<DiffractionRule> rules = {DiffractionRule::Physical};
    if (s.diffraction == DiffractionRule::Traced) rules.push_back(DiffractionRule::Traced);
    std::vector<std::vector<float>> images;
    for (const DiffractionRule rule : rules) {
        const std::string mode = toString(rule);
        const auto t0 = Clock::now();
        double off = 0.0;
        std::string text;
        DiffractionSettings ds;
        ds.rule = rule;
        ds.sensor = to.sensor;
        ds.convolver = s.convolver;
        if (s.convolver && s.fourier.backend) ds.convolverName = s.fourier.backend->describe();
        images.push_back(renderDiffraction(lens, lights, to.frame, ds, orNull(nullptr), &off, &text));
        const double sec = secondsSince(t0);
        double flux = 0.0;
        for (float v : images.back()) flux += v;
        const std::string name = "diffraction-" + mode;
        image::Metadata m = meta;
        m.push_back({"fourierflare:diffraction", text});
        image::writeExr((dir / (name + ".exr")).string(), W, H, {"R", "G", "B"}, images.back(), m);
        image::writePng((dir / (name + ".png")).string(), W, H,
                        image::tonemapPreview(images.back(), image::autoExposure(images.back())), m);
        report["diffraction"][mode] = {{"psf", text}, {"fluxInFrame", flux / lightsFlux}, {"seconds", sec}};
        md += "| " + text + " | " + text::fixed(flux / lightsFlux, 6) + " | " + text::fixed(sec, 2) + " |\n";
    }
    if (images.size() == 2) {
        const auto e = image::compareImages(images[1], images[0]);
        const double scale = image::differenceQuantile(images[1], images[0], 0.999);
        image::writePng((dir / "diff-diffraction-traced-vs-physical.png").string(), W, H,
                        image::differencePicture(images[1], images[0], scale), meta);
        report["diffraction"]["tracedVsPhysical"] = toJson(e);
        md +=
            "\n| comparison | relative L2 | PSNR (dB) | max error / peak | flux ratio |\n|---|---|---|---|---|\n" +
            row("diffraction with the lens's traced wavefront vs aberration-free (what the lens's aberrations change)",
                e);
    }
    return md + "\n";
}

// One comparison: the scene, the traced reference, and the report as each model adds its part.
struct Comparison {
    Comparison(const optics::Lens& l, const ComparisonSettings& settings) : s(settings), lens(l), lights(s.lights) {}
    const ComparisonSettings& s;
    const optics::Lens& lens;
    const std::vector<ghosts::Light>& lights;
    int W = 0, H = 0;
    std::pair<double, double> sensorMm;
    std::filesystem::path dir;
    image::Metadata meta;
    trace::TracedFlareOptions to;
    fourier::FourierSettings base;
    std::vector<float> tracedRgb;
    double exposure = 0.0;
    std::string md, timing;
    nlohmann::json report;
    std::vector<std::pair<std::string, std::vector<double>>> vsFitted, vsTraced; ///< error against N

    void say(const std::string& line) const {
        if (s.say) s.say(line);
    }
    void save(const std::string& name, const std::vector<float>& rgb) const {
        image::writeExr((dir / (name + ".exr")).string(), W, H, {"R", "G", "B"}, rgb, meta);
        image::writePng((dir / (name + ".png")).string(), W, H, image::tonemapPreview(rgb, exposure), meta);
    }

    // The shaped ghosts: every ghost's traced mesh, interpolated over field angle.
    void shaped() {
        auto t0 = Clock::now();
        ghosts::TableSettings ss = s.table;
        ss.sensorSizeMm = sensorMm;
        const ghosts::ShapedTable shapedTable = s.loadShaped(lens, ss);
        const double buildSeconds = secondsSince(t0);
        t0 = Clock::now();
        ghosts::ShapedRender sr;
        const std::vector<float> shapedRgb =
            renderShapedScene(lens, shapedTable, lights, to.frame, to.sensor, &sr, nullptr, s.raster).interleaved();
        const double drawSeconds = secondsSince(t0);
        save("shaped", shapedRgb);
        const auto eShaped = image::compareImages(shapedRgb, tracedRgb);
        const double scale = image::differenceQuantile(shapedRgb, tracedRgb, 0.999);
        image::writePng((dir / "diff-shaped-vs-traced.png").string(), W, H,
                        image::differencePicture(shapedRgb, tracedRgb, scale), meta);
        md += row("shaped vs traced (ghost meshes; " + std::to_string(sr.culled) + " faint ghost instance(s) culled)",
                  eShaped);
        timing += "| shaped ghosts: build (" + std::to_string(shapedTable.ghosts.size()) + " ghosts, " +
                  std::to_string(shapedTable.rays) + " rays) | " + text::fixed(buildSeconds, 3) +
                  " |\n| shaped ghosts: draw (" + std::to_string(sr.triangles) + " triangles) | " +
                  text::fixed(drawSeconds, 3) + " |\n";
        report["shaped"] = toJson(eShaped);
        report["shaped"]["culledShare"] = sr.culledShare;
        report["shaped"]["differenceScale"] = scale;
        report["seconds"]["shapedBuild"] = buildSeconds;
        report["seconds"]["shapedDraw"] = drawSeconds;
        if (!(s.shapedError > 0.0)) return;
        // The shaped hybrid: the dim and soft instances through the Fourier series of a grid.
        t0 = Clock::now();
        ghosts::ShapedRender hr;
        const std::vector<float> hybridRgb =
            renderShapedScene(lens, shapedTable, lights, to.frame, to.sensor, &hr, nullptr, s.raster, s.shapedError)
                .interleaved();
        const double hybridSeconds = secondsSince(t0);
        save("shaped-hybrid", hybridRgb);
        const auto eHybrid = image::compareImages(hybridRgb, tracedRgb);
        const auto eHybridShaped = image::compareImages(hybridRgb, shapedRgb);
        md += row("shaped hybrid vs traced (" + std::to_string(hr.gridded) + " of " + std::to_string(hr.drawn) +
                      " instances through a grid's series, estimated error " +
                      text::scientific(hr.gridErrorEstimate, 2) + ")",
                  eHybrid);
        md += row("shaped hybrid vs shaped", eHybridShaped);
        timing += "| shaped hybrid: draw (" + std::to_string(hr.triangles) + " + " + std::to_string(hr.gridTriangles) +
                  " on the grid) | " + text::fixed(hybridSeconds, 3) + " |\n";
        report["shapedHybrid"] = toJson(eHybrid);
        report["shapedHybrid"]["vsShaped"] = toJson(eHybridShaped);
        report["shapedHybrid"]["gridded"] = hr.gridded;
        report["shapedHybrid"]["estimatedError"] = hr.gridErrorEstimate;
        report["seconds"]["shapedHybridDraw"] = hybridSeconds;
    }

    // One profile's fitted and Fourier images against the reference, and its error against N.
    void compareProfile(ghosts::Profile profile, const ghosts::GhostTable& tab, const std::vector<int>& ns) {
        const trace::ImageFrame frame{W, H, sensorMm.first / W};
        const std::string name = ghosts::toString(profile);
        const auto ghosts = fourierGhosts(ghosts::instantiate(tab, lights, frame, profile));
        auto t0 = Clock::now();
        const fourier::FlareImage fitted = fourier::renderDirect(ghosts, W, H);
        const double fittedSeconds = secondsSince(t0);
        const fourier::FourierRender four = fourier::renderFourier(ghosts, W, H, base);
        const std::vector<float> fittedRgb = fitted.interleaved(), fourierRgb = four.image.interleaved();
        save("fitted-" + name, fittedRgb);
        save("fourier-" + name, fourierRgb);
        const auto eFit = image::compareImages(fittedRgb, tracedRgb),
                   eTrunc = image::compareImages(fourierRgb, fittedRgb),
                   eTotal = image::compareImages(fourierRgb, tracedRgb);
        if (base.basis == fourier::Basis::Bessel) {
            // The Bessel basis draws each ghost isotropic: separate that model change from the truncation.
            auto iso = ghosts;
            for (auto& k : iso)
                for (int c = 0; c < 3; ++c) k.widthX[c] = k.widthY[c] = std::sqrt(k.widthX[c] * k.widthY[c]);
            const std::vector<float> isoRgb = fourier::renderDirect(iso, W, H).interleaved();
            const auto eIso = image::compareImages(isoRgb, fittedRgb),
                       eTruncIso = image::compareImages(fourierRgb, isoRgb);
            md += row("fitted " + name + " made isotropic vs fitted (the Bessel basis's model)", eIso) +
                  row("fourier-bessel " + name + " vs isotropic fitted (truncation)", eTruncIso);
            report["profiles"][name]["isotropicVsFitted"] = toJson(eIso);
            report["profiles"][name]["fourierVsIsotropic"] = toJson(eTruncIso);
        }
        // Difference pictures, each scaled to its own 99.9th percentile of |luminance difference|.
        const std::vector<std::pair<std::string, std::pair<const std::vector<float>*, const std::vector<float>*>>>
            diffs = {{"diff-fitted-" + name + "-vs-traced", {&fittedRgb, &tracedRgb}},
                     {"diff-fourier-" + name + "-vs-fitted", {&fourierRgb, &fittedRgb}},
                     {"diff-fourier-" + name + "-vs-traced", {&fourierRgb, &tracedRgb}}};
        nlohmann::json scales;
        for (const auto& [file, pair] : diffs) {
            const double scale = image::differenceQuantile(*pair.first, *pair.second, 0.999);
            image::writePng((dir / (file + ".png")).string(), W, H,
                            image::differencePicture(*pair.first, *pair.second, scale), meta);
            scales[file] = scale;
        }
        const std::string truncation = base.basis == fourier::Basis::Bessel
                                           ? " vs fitted (isotropic model + truncation)"
                                           : " vs fitted (truncation)";
        md += row("fitted " + name + " vs traced (profile model)", eFit) + row("fourier " + name + truncation, eTrunc) +
              row("fourier " + name + " vs traced (total)", eTotal);
        timing += "| fitted " + name + " (direct, " + std::to_string(ghosts.size()) + " ghosts) | " +
                  text::fixed(fittedSeconds, 3) + " |\n";
        timing += "| fourier " + name + " (" + four.describe() + ") | " + text::fixed(four.seconds.total(), 3) +
                  " (accumulate " + text::fixed(four.seconds.accumulate, 3) + ", evaluate " +
                  text::fixed(four.seconds.evaluate, 3) + ", direct " + text::fixed(four.seconds.direct, 3) + ") |\n";
        nlohmann::json& p = report["profiles"][name];
        p["ghosts"] = ghosts.size();
        p["fittedVsTraced"] = toJson(eFit);
        p["fourierVsFitted"] = toJson(eTrunc);
        p["fourierVsTraced"] = toJson(eTotal);
        p["fourier"] = {{"plan", four.describe()},
                        {"n", four.plan.n},
                        {"m", four.plan.m},
                        {"periodX", four.plan.periodX},
                        {"periodY", four.plan.periodY},
                        {"throughFourier", four.fourierCount()},
                        {"direct", four.directCount()},
                        {"culled", four.culledCount()},
                        {"coarseLevel", four.coarse ? four.coarse->describe() : std::string()},
                        {"evaluation", fourier::toString(four.plan.evaluation)}};
        p["seconds"] = {{"fitted", fittedSeconds},
                        {"fourier", four.seconds.total()},
                        {"accumulate", four.seconds.accumulate},
                        {"evaluate", four.seconds.evaluate},
                        {"direct", four.seconds.direct}};
        p["differenceScales"] = scales;
        // Error against N: every ghost through Fourier with all N terms (no hybrid, no trimming; those
        // that would wrap into the frame on the coarse level), the automatic period: the truncation error.
        std::vector<double> errFit, errTraced;
        for (int n : ns) {
            fourier::FourierSettings sweep = base;
            sweep.fixedN = n;
            sweep.hybrid = false;
            sweep.trimFraction = 0.0;
            const fourier::FourierRender r = fourier::renderFourier(ghosts, W, H, sweep);
            const std::vector<float> rgb = r.image.interleaved();
            const auto a = image::compareImages(rgb, fittedRgb), b = image::compareImages(rgb, tracedRgb);
            errFit.push_back(a.relativeL2);
            errTraced.push_back(b.relativeL2);
            p["errorVsN"].push_back({{"n", n},
                                     {"m", r.plan.m},
                                     {"vsFitted", toJson(a)},
                                     {"vsTraced", toJson(b)},
                                     {"seconds", r.seconds.total()}});
        }
        vsFitted.push_back({name + " vs fitted", errFit});
        vsTraced.push_back({name + " vs traced", errTraced});
        say(name + ": fitted vs traced " + text::fixed(eFit.relativeL2, 4) + ", fourier vs fitted " +
            text::fixed(eTrunc.relativeL2, 6) + " (" + four.describe() + ")");
    }

    // The error-against-N table, the wall times and the files; writes the report.
    void finish(const std::vector<int>& ns) {
        md +=
            "## Error against the number of terms\n\nEvery ghost through Fourier with N terms along x (M in proportion "
            "to the periods), no hybrid "
            "split and no per-ghost trimming (ghosts whose copies would reach the frame on a period of twice its size "
            "go "
            "to a coarse level "
            "with its own period and terms, the same in every row); relative L2 against the fitted (truncation alone) "
            "and the traced image.\n\n| N |";
        for (const auto& series : vsFitted) md += " " + series.first + " |";
        for (const auto& series : vsTraced) md += " " + series.first + " |";
        md += "\n|---|";
        for (std::size_t i = 0; i < vsFitted.size() + vsTraced.size(); ++i) md += "---|";
        md += "\n";
        for (std::size_t i = 0; i < ns.size(); ++i) {
            md += "| " + std::to_string(ns[i]) + " |";
            for (const auto& series : vsFitted) md += " " + text::scientific(series.second[i], 3) + " |";
            for (const auto& series : vsTraced) md += " " + text::scientific(series.second[i], 3) + " |";
            md += "\n";
        }
        md += "\n![error against N](error-vs-n.svg)\n\n## Wall time\n\nFourier backend: " +
              report["fourierBackend"].get<std::string>() + ".\n\n" + timing;
        md += "\n## Files\n\n`traced`, `fitted-*`, `fourier-*` as EXR (linear) and PNG (same exposure); "
              "`diff-A-vs-B.png`: "
              "luminance of A minus B, "
              "red where A is brighter, blue where darker, white where equal, full colour at the 99.9th percentile of "
              "|A − "
              "B| (values in report.json, "
              "`differenceScales`); with --diffraction, `diffraction-physical` (and `diffraction-traced`) as EXR and "
              "PNG.\n";
        auto all = vsFitted;
        all.insert(all.end(), vsTraced.begin(), vsTraced.end());
        writeFileAtomic((dir / "error-vs-n.svg").string(), errorPlot(ns, all, base.error));
        writeFileAtomic((dir / "report.json").string(), report.dump(2) + "\n");
        writeFileAtomic((dir / "report.md").string(), md);
        say("wrote " + (dir / "report.md").string());
    }
};

} // namespace

std::filesystem::path reportFolder(const std::string& output) {
    namespace fs = std::filesystem;
    const fs::path dir(output);
    if (fs::exists(dir) && !fs::is_directory(dir))
        throw Error(ErrorKind::Usage, "the report folder '" + output + "' exists and is not a folder");
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw Error(ErrorKind::Runtime, "cannot create the report folder '" + output + "': " + ec.message());
    return dir;
}

nlohmann::json compareFlares(const optics::Lens& lens, const ComparisonSettings& settings,
                             const std::filesystem::path& dir) {
    ComparisonSettings s = settings;
    if (!s.loadTable)
        s.loadTable = [](const optics::Lens& l, const ghosts::TableSettings& t) {
            return ghosts::tableFor(l, t, true, {}, orNull(nullptr));
        };
    if (!s.loadShaped)
        s.loadShaped = [](const optics::Lens& l, const ghosts::TableSettings& t) {
            return ghosts::shapedTableFor(l, t, true, orNull(nullptr));
        };
    std::sort(s.ns.begin(), s.ns.end());
    if (s.width < 8 || s.height < 8 || s.width > 8192 || s.height > 8192)
        throw Error(ErrorKind::Usage, "the frame must be 8..8192 pixels on each side");
    if (s.lights.empty()) throw Error(ErrorKind::Usage, "give at least one light to compare");
    if (s.ns.empty()) throw Error(ErrorKind::Usage, "give at least one N for the error against N");
    for (int n : s.ns)
        if (n < 1 || n > 2048) throw Error(ErrorKind::Usage, "each N of the sweep must be 1..2048");
    Comparison c(lens, s);
    c.W = s.width;
    c.H = s.height;
    const std::vector<int>& ns = s.ns;
    c.dir = dir;
    c.sensorMm = s.sensorMm;
    c.meta = {{"Software", std::string("fourierflare ") + kVersion},
              {"fourierflare:commandLine", s.commandLine},
              {"fourierflare:lens", c.lens.file},
              {"fourierflare:lensHash", c.lens.contentHash}};

    // Traced reference.
    auto t0 = Clock::now();
    c.to.frame = {c.W, c.H, c.sensorMm.first / c.W};
    c.to.grid = s.grid;
    c.to.sampling = s.sampling;
    c.to.sensor = s.table.sensor;
    c.to.coating = s.table.coating;
    const TracedScene tracedScene = renderTracedScene(c.lens, c.lights, c.to);
    const double tracedSeconds = secondsSince(t0);
    c.say("traced " + std::to_string(c.lights.size()) + " light(s) in " + text::fixed(tracedSeconds, 2) + " s (" +
          tracedScene.describeRefinement() + ")");
    // The reference's own error: the traced render against one with the refinement doubled.
    t0 = Clock::now();
    trace::TracedFlareOptions refined = c.to;
    refined.refinement = 2.0;
    const std::vector<float> checkRgb = renderTracedScene(c.lens, c.lights, refined).image.interleaved();
    const double checkSeconds = secondsSince(t0);

    t0 = Clock::now();
    const ghosts::GhostTable tab = s.loadTable(c.lens, s.table);
    const double tableSeconds = secondsSince(t0);
    c.base = s.fourier;

    c.tracedRgb = tracedScene.image.interleaved();
    c.exposure = image::autoExposure(c.tracedRgb);
    c.save("traced", c.tracedRgb);
    const image::ImageError eReference = image::compareImages(c.tracedRgb, checkRgb);
    c.say("the traced reference against one refined twice as far: relative L2 " +
          text::scientific(eReference.relativeL2, 3) + ", flux ratio " + text::fixed(eReference.fluxRatio, 5));

    nlohmann::json& report = c.report;
    report["tool"] = std::string("fourierflare ") + kVersion;
    report["commandLine"] = s.commandLine;
    report["lens"] = {{"file", c.lens.file}, {"name", c.lens.name}, {"hash", c.lens.contentHash}};
    report["frame"] = {{"width", c.W}, {"height", c.H}, {"sensorMm", {c.sensorMm.first, c.sensorMm.second}}};
    for (const auto& l : c.lights) report["lights"].push_back({{"x", l.xPx}, {"y", l.yPx}, {"flux", l.flux}});
    report["budget"] = c.base.error;
    report["previewExposureEv"] = c.exposure;
    report["seconds"] = {{"traced", tracedSeconds}, {"tracedRefined", checkSeconds}, {"table", tableSeconds}};
    report["reference"] = toJson(eReference);
    report["reference"]["against"] = "the traced render with twice the refinement (--refine 2)";
    report["fourierBackend"] = c.base.backend ? c.base.backend->describe() : std::string("cpu");
    std::string& md = c.md;
    md = "# Flare comparison: " + c.lens.name + "\n\n";
    md += "Lens `" + c.lens.file + "`, frame " + std::to_string(c.W) + " x " + std::to_string(c.H) + " px over " +
          text::fixed(c.sensorMm.first, 1) + " x " + text::fixed(c.sensorMm.second, 1) + " mm, " +
          std::to_string(c.lights.size()) +
          " light(s). Images are flux per pixel relative to each light's "
          "direct image; previews share one exposure (" +
          text::fixed(c.exposure, 2) + " EV, from the traced image).\n\n";
    if (!s.lightsNote.empty()) md += s.lightsNote + "\n\n";
    md += "- **traced**: every ghost ray-traced (adaptive pupil grids from " + std::to_string(s.grid) +
          "² cells, 450/550/650 nm; " + tracedScene.describeRefinement() + ") and rasterised — the reference.\n";
    md += "- **shaped**: every ghost as the mesh its rays draw on the sensor (pupil grids with the apertures' edges "
          "clipped exactly, "
          "interpolated over field angle; docs/ghost-table.md), drawn with the traced renderer's raster.\n";
    md += "- **fitted**: the ghost table's profiles (per ghost, field angle and wavelength), axis-aligned, drawn "
          "directly over every pixel (no truncation).\n";
    md += "- **fourier**: the same profiles aggregated through the separable Fourier series (budget " +
          text::roundTrip(c.base.error) + ", hybrid).\n\n";
    md += "| comparison | relative L2 | PSNR (dB) | max error / peak | flux ratio |\n|---|---|---|---|---|\n";
    md += row("traced vs traced refined twice as far (the reference's own error)", eReference);

    c.timing = "| mode | seconds |\n|---|---|\n| traced | " + text::fixed(tracedSeconds, 3) +
               " |\n| traced, refined twice as far (the reference's check) | " + text::fixed(checkSeconds, 3) +
               " |\n| ghost table (load or build) | " + text::fixed(tableSeconds, 3) + " |\n";
    c.shaped();
    // The Bessel basis takes Gaussian ghosts only.
    std::vector<ghosts::Profile> profiles = {ghosts::Profile::Gaussian};
    if (c.base.basis == fourier::Basis::Separable) profiles.push_back(ghosts::Profile::Cos2);
    for (const auto profile : profiles) c.compareProfile(profile, tab, ns);
    c.md += "\nPSNR uses the reference's peak. Flux ratio = total flux of the image / total flux of the reference.\n\n";
    if (s.diffraction != DiffractionRule::Off) c.md += compareDiffraction(s, c.lens, c.to, c.dir, c.meta, c.report);
    c.finish(ns);
    return c.report;
}

} // namespace ff::scene
