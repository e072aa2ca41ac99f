#include "scene/scene.h"

#include "core/error.h"
#include "core/file_io.h"
#include "core/text.h"
#include "core/units.h"
#include "diffraction/wavefront.h"
#include "fourier/evaluate.h"
#include "fourier/sampled.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace ff::scene {

ghosts::Light parseLight(const std::string& spec) {
    const auto parts = text::split(spec, ',');
    std::vector<double> v;
    for (auto p : parts) {
        const auto x = text::parseNumber(p);
        if (!x || !std::isfinite(*x))
            v.clear(), v.push_back(NAN);
        else
            v.push_back(*x);
    }
    const bool ok =
        (v.size() == 2 || v.size() == 5) && std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
    if (!ok || (v.size() == 5 && (v[2] < 0 || v[3] < 0 || v[4] < 0)))
        throw Error(ErrorKind::Usage,
                    "expected --light X,Y or X,Y,R,G,B (pixels; non-negative RGB flux), got " + text::quoted(spec));
    ghosts::Light l;
    l.xPx = v[0];
    l.yPx = v[1];
    if (v.size() == 5) l.flux = {v[2], v[3], v[4]};
    return l;
}

namespace {

using nlohmann::json;

// The largest lights or ghosts file read: room for millions of ghosts.
constexpr std::uintmax_t kMaxJsonBytes = 256u << 20;

json parseJsonText(std::string_view bytes, const std::string& file) {
    try {
        return json::parse(bytes);
    } catch (const json::parse_error& e) {
        // Byte offset to line:column.
        std::size_t line = 1, col = 1;
        for (std::size_t i = 0; i + 1 < e.byte && i < bytes.size(); ++i) {
            if (bytes[i] == '\n')
                ++line, col = 1;
            else
                ++col;
        }
        std::string what = e.what();
        if (const auto p = what.find("syntax error"); p != std::string::npos) what = what.substr(p);
        throw Error(ErrorKind::Input, SourceLocation{file, static_cast<int>(line), static_cast<int>(col)},
                    "not valid JSON: " + what);
    } catch (const json::exception& e) {
        // A number beyond double's range (out_of_range 406), ...: no position given.
        throw Error(ErrorKind::Input, SourceLocation{file}, std::string("not valid JSON: ") + e.what());
    }
}

// Runs `read` over a parsed document, turning what the JSON library throws on a value of the wrong
// type (type_error) into ff::Error naming the file.
template <class Read>
auto withJsonErrors(const std::string& file, Read read) {
    try {
        return read();
    } catch (const json::exception& e) {
        throw Error(ErrorKind::Input, SourceLocation{file}, std::string("unexpected JSON: ") + e.what());
    }
}

[[noreturn]] void bad(const std::string& file, const std::string& where, const std::string& what) {
    throw Error(ErrorKind::Input, SourceLocation{file}, where + ": " + what);
}

// A number, or [R, G, B] of numbers: three values, each finite and >= 0 (> 0 when positive).
std::array<double, 3> triple(const std::string& file, const std::string& where, const json& v, bool positive) {
    std::array<double, 3> out{};
    if (v.is_number())
        out.fill(v.get<double>());
    else if (v.is_array() && v.size() == 3 && v[0].is_number() && v[1].is_number() && v[2].is_number())
        out = {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
    else
        bad(file, where, "expected a number or [R, G, B]");
    for (double x : out)
        if (!std::isfinite(x) || x < 0.0 || (positive && x == 0.0))
            bad(file, where,
                positive ? "values must be finite and positive" : "values must be finite and non-negative");
    return out;
}

double number(const std::string& file, const std::string& where, const json& obj, const char* key) {
    if (!obj.contains(key) || !obj[key].is_number()) bad(file, where, std::string("expected a number \"") + key + "\"");
    const double v = obj[key].get<double>();
    if (!std::isfinite(v)) bad(file, where, std::string("\"") + key + "\" must be finite");
    return v;
}

const json& list(const std::string& file, const json& doc, const char* key) {
    if (!doc.is_object() || !doc.contains(key) || !doc[key].is_array())
        bad(file, "top level", std::string("expected an object with an array \"") + key + "\"");
    return doc[key];
}

std::vector<ghosts::Light> lightsFrom(const json& doc, const std::string& file) {
    std::vector<ghosts::Light> out;
    const json& lights = list(file, doc, "lights");
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const std::string where = "lights[" + std::to_string(i) + "]";
        if (!lights[i].is_object()) bad(file, where, "expected an object");
        ghosts::Light l;
        l.xPx = number(file, where, lights[i], "x");
        l.yPx = number(file, where, lights[i], "y");
        if (lights[i].contains("flux")) l.flux = triple(file, where + ".flux", lights[i]["flux"], false);
        out.push_back(l);
    }
    return out;
}

std::vector<fourier::Ghost> ghostsFrom(const json& doc, const std::string& file) {
    std::vector<fourier::Ghost> out;
    const json& ghosts = list(file, doc, "ghosts");
    for (std::size_t i = 0; i < ghosts.size(); ++i) {
        const std::string where = "ghosts[" + std::to_string(i) + "]";
        const json& g = ghosts[i];
        if (!g.is_object()) bad(file, where, "expected an object");
        fourier::Ghost k;
        k.x = number(file, where, g, "x");
        k.y = number(file, where, g, "y");
        const std::string profile = g.value("profile", std::string("gaussian"));
        if (profile != "gaussian" && profile != "cos2")
            bad(file, where + ".profile", "expected \"gaussian\" or \"cos2\", got \"" + profile + "\"");
        k.shape = profile == "gaussian" ? fourier::Shape::Gaussian : fourier::Shape::Cos2;
        if (!g.contains("widthX") || !g.contains("widthY"))
            bad(file, where, "expected \"widthX\" and \"widthY\" (pixels)");
        k.widthX = triple(file, where + ".widthX", g["widthX"], true);
        k.widthY = triple(file, where + ".widthY", g["widthY"], true);
        if (g.contains("flux") == g.contains("peak")) bad(file, where, "give exactly one of \"flux\" and \"peak\"");
        if (g.contains("flux"))
            k.flux = triple(file, where + ".flux", g["flux"], false);
        else {
            const auto peak = triple(file, where + ".peak", g["peak"], false);
            for (int c = 0; c < 3; ++c)
                k.flux[c] = peak[c] * fourier::profileIntegral(k.shape, k.widthX[c]) *
                            fourier::profileIntegral(k.shape, k.widthY[c]);
        }
        out.push_back(k);
    }
    return out;
}

} // namespace

std::vector<ghosts::Light> readLightsJson(const std::string& file) {
    return parseLightsJson(readFileBytes(file, kMaxJsonBytes), file);
}

std::vector<ghosts::Light> parseLightsJson(std::string_view text, const std::string& file) {
    const json doc = parseJsonText(text, file);
    return withJsonErrors(file, [&] { return lightsFrom(doc, file); });
}

std::vector<fourier::Ghost> readGhostsJson(const std::string& file) {
    return parseGhostsJson(readFileBytes(file, kMaxJsonBytes), file);
}

std::vector<fourier::Ghost> parseGhostsJson(std::string_view text, const std::string& file) {
    const json doc = parseJsonText(text, file);
    return withJsonErrors(file, [&] { return ghostsFrom(doc, file); });
}

std::vector<fourier::Ghost> fourierGhosts(const std::vector<ghosts::GhostInstance>& instances) {
    std::vector<fourier::Ghost> out;
    out.reserve(instances.size());
    for (const auto& gi : instances) {
        fourier::Ghost g;
        g.x = gi.xPx;
        g.y = gi.yPx;
        g.shape = gi.profile == ghosts::Profile::Gaussian ? fourier::Shape::Gaussian : fourier::Shape::Cos2;
        const double c = std::cos(gi.radialAngle), s = std::sin(gi.radialAngle);
        bool usable = true;
        for (int ch = 0; ch < 3; ++ch) {
            const double r = gi.widthR[ch], t = gi.widthT[ch];
            g.widthX[ch] = std::sqrt(r * r * c * c + t * t * s * s);
            g.widthY[ch] = std::sqrt(r * r * s * s + t * t * c * c);
            g.flux[ch] = gi.flux[ch];
            usable = usable && g.widthX[ch] > 0.0 && g.widthY[ch] > 0.0 && std::isfinite(g.widthX[ch]) &&
                     std::isfinite(g.widthY[ch]);
        }
        if (usable) out.push_back(g);
    }
    return out;
}

namespace {

void addTraced(TracedScene& scene, const trace::TracedFlare& f, const std::array<double, 3>& flux) {
    for (std::size_t p = 0; p < scene.image.pixels(); ++p)
        for (int c = 0; c < 3; ++c) scene.image.channel[c][p] += static_cast<float>(flux[c] * f.rgb[p * 3 + c]);
    scene.ghostCount = f.ghostCount;
    scene.wavelengths = f.wavelengthsNm.size();
    for (const auto& s : f.stats) scene.inFrame += s.deposited, scene.outside += s.offImage;
    scene.samples += f.samples;
    scene.culled += f.culled;
    scene.budgetHits += f.budgetHits;
    scene.culledShare = std::max(scene.culledShare, f.culledShare);
    scene.maxDepth = std::max(scene.maxDepth, f.maxDepth);
}

} // namespace

std::string TracedScene::describeRefinement() const {
    std::string s = std::to_string(samples) + " rays, refined to depth " + std::to_string(maxDepth) + "; culled " +
                    std::to_string(culled) + " ghost(s) holding " + text::scientific(culledShare, 2) +
                    " of the ghost flux";
    if (budgetHits) s += "; the ray budget stopped " + std::to_string(budgetHits) + " ghost refinement(s)";
    return s;
}

TracedScene renderTracedField(const optics::Lens& lens, const trace::TracedFlareOptions& o) {
    TracedScene scene;
    scene.image = fourier::FlareImage(o.frame.width, o.frame.height);
    addTraced(scene, trace::renderTracedFlare(lens, o), {1.0, 1.0, 1.0});
    return scene;
}

TracedScene renderTracedScene(const optics::Lens& lens, const std::vector<ghosts::Light>& lights,
                              trace::TracedFlareOptions o) {
    TracedScene scene;
    scene.image = fourier::FlareImage(o.frame.width, o.frame.height);
    const double sensorZ = trace::sensorPlaneZ(lens, o.sensor);
    for (const ghosts::Light& l : lights) {
        const glm::dvec2 s = o.frame.pixelToSensor(l.xPx, l.yPx);
        o.field = trace::fieldForSensorPoint(lens, sensorZ, s.x, s.y);
        addTraced(scene, trace::renderTracedFlare(lens, o), l.flux);
    }
    return scene;
}

fourier::FlareImage renderShapedScene(const optics::Lens& lens, const ghosts::ShapedTable& table,
                                      const std::vector<ghosts::Light>& lights, const trace::ImageFrame& frame,
                                      trace::SensorPlane sensor, ghosts::ShapedRender* stats, std::size_t* outside,
                                      ghosts::PolygonRaster* raster, double gridError) {
    const double sensorZ = trace::sensorPlaneZ(lens, sensor);
    std::vector<ghosts::ShapedLight> shaped;
    if (outside) *outside = 0;
    for (const ghosts::Light& l : lights) {
        const glm::dvec2 s = frame.pixelToSensor(l.xPx, l.yPx);
        try {
            const trace::Field f = trace::fieldForSensorPoint(lens, sensorZ, s.x, s.y);
            // Beyond the table's field the ghosts are not known (the table spans the sensor's
            // half-diagonal where the lens images it).
            if (outside && !table.covers(f)) {
                ++*outside;
                continue;
            }
            shaped.push_back({f, l.flux});
        } catch (const Error&) {
            if (!outside) throw;
            ++*outside;
        }
    }
    return drawShaped(table, shaped, frame, stats, raster, gridError);
}

fourier::FlareImage drawShaped(const ghosts::ShapedTable& table, const std::vector<ghosts::ShapedLight>& lights,
                               const trace::ImageFrame& frame, ghosts::ShapedRender* stats,
                               ghosts::PolygonRaster* raster, double gridError) {
    ghosts::ShapedRenderSettings settings;
    settings.gridError = gridError;
    if (gridError > 0.0) {
        // The Fourier period: the frame and a margin of kShapedGridMargin cells on every side, in
        // whole cells of an FFT-friendly number, the cells' centres on multiples of the step.
        auto& g = settings.grid;
        g.step = kShapedGridStep;
        const auto cells = [&](int pixels) {
            return fourier::fftFriendly((pixels + kShapedGridStep - 1) / kShapedGridStep + 2 * kShapedGridMargin);
        };
        g.width = cells(frame.width);
        g.height = cells(frame.height);
        g.x0 = -(std::floor((g.width * g.step - frame.width) / (2.0 * g.step)) + 0.5) * g.step;
        g.y0 = -(std::floor((g.height * g.step - frame.height) / (2.0 * g.step)) + 0.5) * g.step;
    }
    ghosts::ShapedRender r = ghosts::renderShaped(table, lights, frame, settings, raster);
    fourier::FlareImage image(frame.width, frame.height);
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < image.pixels(); ++p) image.channel[c][p] = static_cast<float>(r.channel[c][p]);
    if (r.gridded > 0) {
        // The gridded instances reach the frame through their series, every term below the grid's
        // Nyquist frequency kept.
        const auto& g = settings.grid;
        fourier::SampledGhost cells;
        cells.x0 = g.x0;
        cells.y0 = g.y0;
        cells.step = g.step;
        cells.width = g.width;
        cells.height = g.height;
        cells.values.resize(static_cast<std::size_t>(g.width) * g.height * 3);
        for (std::size_t k = 0; k < cells.values.size(); ++k)
            cells.values[k] = static_cast<float>(r.grid[k % 3][k / 3]);
        fourier::Coefficients z;
        z.n = g.width / 2;
        z.m = g.height / 2;
        z.periodX = double(g.width) * g.step;
        z.periodY = double(g.height) * g.step;
        for (auto& ch : z.z) ch.assign(static_cast<std::size_t>(4) * z.n * z.m, 0.0);
        fourier::accumulateSampledGrid(cells, z);
        fourier::evaluate(z, fourier::Evaluation::Fft, image, fourier::Write::Add);
    }
    for (auto& ch : image.channel)
        for (float& v : ch) v = std::max(0.0f, v);
    if (stats) {
        for (auto& ch : r.channel) ch = {};
        for (auto& ch : r.grid) ch = {};
        *stats = std::move(r);
    }
    return image;
}

namespace {

// Calls put(x, y, w) for the pixels (x, y) of the light's bilinear footprint (pixel centres at
// integer + 0.5, offset by the origin) and their weights w; nothing for a light 1e9 px away.
template <class Put>
void footprint(const ghosts::Light& l, double originX, double originY, Put&& put) {
    const double fx = l.xPx - originX - 0.5, fy = l.yPx - originY - 0.5;
    const double x0 = std::floor(fx), y0 = std::floor(fy);
    if (!(std::abs(x0) < 1e9 && std::abs(y0) < 1e9)) return;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i)
            put(x0 + i, y0 + j, (i ? fx - x0 : 1.0 - (fx - x0)) * (j ? fy - y0 : 1.0 - (fy - y0)));
}

} // namespace

std::vector<float> splatLights(const std::vector<ghosts::Light>& lights, int width, int height, double originX,
                               double originY) {
    std::vector<float> rgb(static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0) * 3, 0.0f);
    for (const auto& l : lights)
        footprint(l, originX, originY, [&](double x, double y, double w) {
            if (x < 0 || y < 0 || x >= width || y >= height) return;
            const std::size_t p = static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x);
            for (int c = 0; c < 3; ++c) rgb[p * 3 + c] += static_cast<float>(w * l.flux[c]);
        });
    return rgb;
}

void addOffFrameLights(const std::vector<ghosts::Light>& lights, int width, int height, double originX, double originY,
                       const diffraction::Psf& psf, double gain, std::vector<float>& out, double* offFrame) {
    for (const ghosts::Light& l : lights)
        footprint(l, originX, originY, [&](double x, double y, double w) {
            if ((x >= 0 && y >= 0 && x < width && y < height) || w == 0.0) return;
            const double k = gain * w;
            diffraction::addOutsideLight(psf, static_cast<long long>(x), static_cast<long long>(y),
                                         {k * l.flux[0], k * l.flux[1], k * l.flux[2]}, width, height, out, offFrame);
        });
}

std::string describePsf(const diffraction::Aperture& aperture, const diffraction::Psf& psf,
                        const diffraction::PupilMask* dirt) {
    return "working f/" + text::fixed(aperture.fNumber, 2) + ", " +
           (aperture.blades >= 3 ? std::to_string(aperture.blades) + " blades" : std::string("circular iris")) + "; " +
           std::to_string(psf.wavelengthsNm.size()) + " wavelengths " +
           text::fixed(*std::min_element(psf.wavelengthsNm.begin(), psf.wavelengthsNm.end()), 0) + "-" +
           text::fixed(*std::max_element(psf.wavelengthsNm.begin(), psf.wavelengthsNm.end()), 0) +
           " nm; the transform's near field (to " + std::to_string(psf.radius) + " px) joined from " +
           text::fixed(0.2 * psf.radius, 0) + " px to the far field (" +
           (aperture.blades >= 3 ? "the blades' edge diffraction" : "the Airy pattern's mean") + ", at " +
           text::scientific(psf.edge, 2) + " of the centre there) reaching the frame's edges" +
           (dirt && !dirt->empty() ? "; dirt on the front element (" + dirt->key + ")" : std::string());
}

} // namespace ff::scene
