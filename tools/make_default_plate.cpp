// Generates data/night-street.exr, the default plate of `scripts/run-main.sh`: a 1280 x 720 half-float
// scene-linear EXR of a street at dusk — a low sun on the horizon, sodium street lamps, lit windows,
// car headlights and a traffic light — drawn analytically (no noise, deterministic). Values are
// scene-linear with diffuse white near 1: the sky and walls stay below 1, the light sources are
// hundreds to thousands, as in a real HDR capture.
//
// Usage: make-default-plate OUTPUT.exr

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

namespace {

constexpr int kW = 1280, kH = 720;
constexpr int kHorizon = 400;

using Rgb = std::array<float, 3>;

struct Canvas {
    std::vector<float> px = std::vector<float>(static_cast<std::size_t>(kW) * kH * 3, 0.0f);
    void set(int x, int y, const Rgb& c) {
        if (x < 0 || y < 0 || x >= kW || y >= kH) return;
        for (int i = 0; i < 3; ++i) px[(static_cast<std::size_t>(y) * kW + x) * 3 + i] = c[i];
    }
    void add(int x, int y, const Rgb& c, float w) {
        if (x < 0 || y < 0 || x >= kW || y >= kH) return;
        for (int i = 0; i < 3; ++i) px[(static_cast<std::size_t>(y) * kW + x) * 3 + i] += c[i] * w;
    }
    // A disc of constant radiance with a one-pixel antialiased edge.
    void disc(double cx, double cy, double r, const Rgb& c) {
        for (int y = static_cast<int>(cy - r - 2); y <= static_cast<int>(cy + r + 2); ++y)
            for (int x = static_cast<int>(cx - r - 2); x <= static_cast<int>(cx + r + 2); ++x) {
                const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
                const double cover = std::clamp(r + 0.5 - d, 0.0, 1.0);
                if (cover > 0.0) {
                    if (x < 0 || y < 0 || x >= kW || y >= kH) continue;
                    for (int i = 0; i < 3; ++i) {
                        float& v = px[(static_cast<std::size_t>(y) * kW + x) * 3 + i];
                        v = static_cast<float>(v * (1.0 - cover) + c[i] * cover);
                    }
                }
            }
    }
    void rect(int x0, int y0, int x1, int y1, const Rgb& c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
    // A soft glow (light scattered in the air or pooled on the ground): Gaussian falloff.
    void glow(double cx, double cy, double sx, double sy, const Rgb& c) {
        for (int y = std::max(0, static_cast<int>(cy - 4 * sy)); y < std::min(kH, static_cast<int>(cy + 4 * sy)); ++y)
            for (int x = std::max(0, static_cast<int>(cx - 4 * sx)); x < std::min(kW, static_cast<int>(cx + 4 * sx));
                 ++x) {
                const double dx = (x + 0.5 - cx) / sx, dy = (y + 0.5 - cy) / sy;
                add(x, y, c, static_cast<float>(std::exp(-0.5 * (dx * dx + dy * dy))));
            }
    }
};

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make-default-plate OUTPUT.exr\n");
        return 2;
    }
    Canvas c;
    // Sky: deep blue overhead to a warm band at the horizon, brightest towards the sun (right).
    for (int y = 0; y < kHorizon; ++y)
        for (int x = 0; x < kW; ++x) {
            const double t = double(y) / kHorizon, sunward = std::exp(-std::pow((x - 1060.0) / 420.0, 2));
            const double warm = std::pow(t, 3.0) * (0.25 + 0.75 * sunward);
            c.set(x, y,
                  {static_cast<float>(0.012 + 0.42 * warm), static_cast<float>(0.018 + 0.20 * warm),
                   static_cast<float>(0.05 + 0.06 * warm)});
        }
    // The low sun on the horizon haze: some 1e5 times the sky, as the real one (half float tops out at 65504).
    c.glow(1060, 372, 60, 22, {1.6f, 0.7f, 0.25f});
    c.disc(1060, 372, 11, {60000.0f, 40000.0f, 18000.0f}); // near half float's largest value, as a captured sun
    // Buildings on the left, dark, with windows: most dimly lit (below the light threshold), a few bright.
    const int buildings[][3] = {{0, 150, 170}, {150, 260, 230}, {260, 420, 130}, {420, 520, 260}, {520, 640, 200}};
    for (const auto& b : buildings) {
        c.rect(b[0], b[2], b[1], kHorizon + 40, {0.006f, 0.006f, 0.008f});
        int k = 0;
        for (int y = b[2] + 14; y + 12 < kHorizon + 20; y += 26)
            for (int x = b[0] + 10; x + 12 < b[1] - 6; x += 22, ++k) {
                if ((k * 7 + b[0]) % 5 == 0) continue; // dark window
                const bool bright = (k * 13 + b[2]) % 17 == 0;
                c.rect(x, y, x + 10, y + 14, bright ? Rgb{9.0f, 6.5f, 3.5f} : Rgb{0.55f, 0.42f, 0.25f});
            }
    }
    // Street: asphalt in perspective towards a vanishing point near the sun.
    for (int y = kHorizon + 40; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const double depth = double(y - kHorizon) / (kH - kHorizon);
            c.set(x, y,
                  {static_cast<float>(0.010 + 0.02 * depth), static_cast<float>(0.010 + 0.018 * depth),
                   static_cast<float>(0.012 + 0.016 * depth)});
        }
    // Sodium street lamps along the left kerb, receding: pole, a bright lamp head, a pool of light.
    for (int i = 0; i < 6; ++i) {
        const double s = std::pow(0.72, i); // perspective scale
        const double x = 720.0 - 560.0 * s, base = kHorizon + 40 + 280 * s;
        const double top = base - 330 * s;
        c.rect(static_cast<int>(x - 2 * s), static_cast<int>(top), static_cast<int>(x + 2 * s) + 1,
               static_cast<int>(base), {0.004f, 0.004f, 0.004f});
        c.glow(x, base - 4 * s, 90 * s, 18 * s, {0.45f, 0.28f, 0.08f});
        c.glow(x + 10 * s, top, 26 * s, 26 * s, {0.9f, 0.55f, 0.15f});
        c.disc(x + 10 * s, top, std::max(1.6, 6.0 * s), {900.0f, 560.0f, 160.0f});
    }
    // An oncoming car: two headlights and their reflections on the road.
    c.glow(930, 560, 120, 14, {0.35f, 0.36f, 0.40f});
    c.disc(890, 548, 5.5, {1500.0f, 1550.0f, 1700.0f});
    c.disc(968, 548, 5.5, {1500.0f, 1550.0f, 1700.0f});
    // A traffic light at red, and a green shop sign.
    c.rect(1180, 380, 1186, 560, {0.004f, 0.004f, 0.004f});
    c.disc(1183, 372, 4.0, {650.0f, 30.0f, 12.0f});
    c.glow(1183, 372, 12, 12, {1.2f, 0.06f, 0.02f});
    c.rect(300, 452, 380, 462, {3.0f, 18.0f, 6.0f});

    OIIO::ImageSpec spec(kW, kH, 3, OIIO::TypeDesc::HALF);
    spec.channelnames = {"R", "G", "B"};
    spec.attribute("compression", "zip");
    spec.attribute("Software", "FourierFlare tools/make_default_plate.cpp");
    spec.attribute(
        "ImageDescription",
        "Synthetic night street with a low sun, street lamps, windows, headlights and a traffic light (scene-linear)");
    auto out = OIIO::ImageOutput::create(argv[1]);
    if (!out || !out->open(argv[1], spec) || !out->write_image(OIIO::TypeDesc::FLOAT, c.px.data()) || !out->close()) {
        std::fprintf(stderr, "make-default-plate: cannot write %s: %s\n", argv[1],
                     out ? out->geterror().c_str() : OIIO::geterror().c_str());
        return 1;
    }
    return 0;
}
