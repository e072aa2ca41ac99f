#include "scene/flare_render.h"

#include "core/error.h"
#include "core/text.h"
#include "core/units.h"
#include "fourier/backend.h"
#include "fourier/render.h"
#include "ghosts/shaped_cache.h"
#include "optics/lens_loader.h"

namespace ff::scene {

RenderedFlare renderGhosts(const std::vector<fourier::Ghost>& ghosts, const FlareSettings& s) {
    const int W = s.traced.frame.width, H = s.traced.frame.height;
    RenderedFlare r;
    r.ghosts = ghosts.size();
    if (s.mode == RenderMode::Fitted) {
        r.image = fourier::renderDirect(ghosts, W, H);
        return r;
    }
    r.plan = fourier::renderFourier(ghosts, W, H, s.fourier);
    r.image = std::move(r.plan->image);
    r.plan->image = {};
    return r;
}

RenderedFlare renderFromTable(const ghosts::GhostTable& table, const std::vector<ghosts::Light>& lights,
                              const FlareSettings& s) {
    if (s.mode != RenderMode::Fitted && s.mode != RenderMode::Fourier)
        throw Error(ErrorKind::Usage,
                    std::string("a ghost table renders its fits (fitted or fourier), not ") + toString(s.mode));
    return renderGhosts(fourierGhosts(ghosts::instantiate(table, lights, s.traced.frame, s.profile)), s);
}

DiffractionSettings diffractionSettings(const FlareSettings& s) {
    DiffractionSettings d;
    d.rule = s.diffraction;
    d.sensor = s.traced.sensor;
    d.dirt = s.dirt;
    d.convolver = s.convolver;
    d.useCache = s.useCache;
    if (s.convolver && s.fourier.backend) d.convolverName = s.fourier.backend->describe();
    return d;
}

void requireLensFor(const optics::Lens& lens, const FlareSettings& s) {
    const bool anyLens = s.mode == RenderMode::Traced || s.mode == RenderMode::Shaped ||
                         (s.mode == RenderMode::Diffraction && s.diffraction == DiffractionRule::Physical);
    if (!anyLens) optics::requireTraceable(lens);
}

RenderedFlare renderFlare(const optics::Lens& lens, const std::vector<ghosts::Light>& lights, const FlareSettings& s) {
    const trace::TracedFlareOptions& t = s.traced;
    requireLensFor(lens, s);
    if (s.mode == RenderMode::Fitted || s.mode == RenderMode::Fourier) {
        const ghosts::GhostTable table =
            s.loadTable ? s.loadTable(lens, s.table) : ghosts::tableFor(lens, s.table, s.useCache, {}, orNull(nullptr));
        return renderFromTable(table, lights, s);
    }
    RenderedFlare r;
    if (s.mode == RenderMode::Traced) {
        if (s.field) {
            trace::TracedFlareOptions one = t;
            one.field = *s.field;
            r.traced = renderTracedField(lens, one);
        } else {
            r.traced = renderTracedScene(lens, lights, t);
        }
        r.image = std::move(r.traced.image);
        r.traced.image = {};
    } else if (s.mode == RenderMode::Diffraction) {
        const std::vector<float> spread = renderDiffraction(lens, lights, t.frame, diffractionSettings(s),
                                                            orNull(s.reporter), &r.offFrame, &r.diffractionText);
        r.image = fourier::FlareImage(t.frame.width, t.frame.height);
        for (std::size_t p = 0; p < r.image.pixels(); ++p)
            for (int c = 0; c < 3; ++c) r.image.channel[c][p] = spread[p * 3 + c];
    } else {
        ghosts::TableSettings ss = s.table;
        ss.sensorSizeMm = s.sensorMm;
        const ghosts::ShapedTable tab =
            s.loadShaped ? s.loadShaped(lens, ss) : ghosts::shapedTableFor(lens, ss, s.useCache, orNull(nullptr));
        if (s.field && !tab.covers(*s.field))
            throw Error(ErrorKind::Usage,
                        "field angle " + text::fixed(radToDeg(s.field->angleRad), 2) + " deg is beyond the table's " +
                            (tab.twoDimensional() ? "field (tangents up to " + text::fixed(tab.fieldGrid.maxTanX, 4) +
                                                        " in x, " + text::fixed(tab.fieldGrid.maxTanY, 4) + " in y)"
                                                  : "largest, " + text::fixed(tab.maxAngleDeg, 2) + " deg") +
                            ": raise --max-angle");
        r.image = s.field ? drawShaped(tab, {{*s.field, {1.0, 1.0, 1.0}}}, t.frame, &r.shaped, s.raster)
                          : renderShapedScene(lens, tab, lights, t.frame, t.sensor, &r.shaped, nullptr, s.raster);
        r.shapedStored = tab.ghosts.size();
        r.shapedGhosts = tab.ghostCount;
        r.shapedBytes = tab.bytes();
    }
    return r;
}

} // namespace ff::scene
