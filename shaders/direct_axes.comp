#version 450
// The hybrid path's direct drawing, first pass (docs/gpu.md): every ghost's per-pixel integrals along
// each axis of its footprint, once, for direct_draw.comp to multiply per pixel:
//
//     X_c(i) = alpha_c Int_{i}^{i+1} p(x - x_k; wx_c) dx,   Y_c(j) = Int_{j}^{j+1} p(y - y_k; wy_c) dy,
//
// with p the unit-peak profile. Pixel integrals of the Gaussian exp(-u^2 / 2 s^2):
// s sqrt(pi / 2) [erf(b / s sqrt 2) - erf(a / s sqrt 2)], written with erfc on one side of the centre
// so that tail pixels keep their relative precision (erfc from Abramowitz & Stegun 7.1.26, absolute
// error 1.5e-7; the GPU has no erf). Of cos^2(pi u / 2w) on |u| < w: F(b) - F(a),
// F(u) = u / 2 + (w / 2 pi) sin(pi u / w) with u clamped to the support.
//
// One work group per ghost (a 2-D grid of groups when there are more than 65 535 ghosts); its
// invocations stride over the footprint's columns, then its rows. Ghost k's integrals are
// integral[axes_k .. axes_k + columns) (X) followed by its rows (Y), RGB in xyz.

layout(local_size_x = 64) in;

struct DirectGhost {
    ivec4 box;      // first x, first y, last x, last y (pixels, inclusive), clipped to the frame
    vec2 offset;    // first x - x_k, first y - y_k: the footprint's corner relative to the centre
    float shape;    // 0 Gaussian, 1 cos^2
    int axes;       // index of the ghost's first integral
    vec4 widthX;    // per channel: sigma or half-width w, pixels
    vec4 widthY;
    vec4 peak;      // alpha per channel
};

layout(std430, binding = 0) readonly buffer Ghosts { DirectGhost ghosts[]; };
layout(std430, binding = 2) writeonly buffer Integrals { vec4 integral[]; };

uniform int count;

const float PI = 3.14159265358979;

// erfc(x) for x >= 0, A&S 7.1.26.
float erfcPositive(float x) {
    const float t = 1.0 / (1.0 + 0.3275911 * x);
    const float poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    return poly * exp(-x * x);
}

// Integral of the unit-peak profile over [a, b] (a < b), centred at 0.
float cellIntegral(float shape, float w, float a, float b) {
    if (shape < 0.5) {
        const float k = 1.0 / (sqrt(2.0) * w);
        float d; // erf(b k) - erf(a k)
        if (a >= 0.0) d = erfcPositive(a * k) - erfcPositive(b * k);
        else if (b <= 0.0) d = erfcPositive(-b * k) - erfcPositive(-a * k);
        else d = 2.0 - erfcPositive(b * k) - erfcPositive(-a * k);
        return w * sqrt(0.5 * PI) * d;
    }
    const float ca = clamp(a, -w, w), cb = clamp(b, -w, w);
    return 0.5 * (cb - ca) + w / (2.0 * PI) * (sin(PI * cb / w) - sin(PI * ca / w));
}

void main() {
    const int k = int(gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x);
    if (k >= count) return;
    const DirectGhost g = ghosts[k];
    const int columns = g.box.z - g.box.x + 1, rows = g.box.w - g.box.y + 1;
    for (int i = int(gl_LocalInvocationID.x); i < columns + rows; i += 64) {
        vec4 v = vec4(0.0);
        if (i < columns) {
            const float a = g.offset.x + float(i);
            for (int c = 0; c < 3; ++c) v[c] = g.peak[c] * cellIntegral(g.shape, g.widthX[c], a, a + 1.0);
        } else {
            const float a = g.offset.y + float(i - columns);
            for (int c = 0; c < 3; ++c) v[c] = cellIntegral(g.shape, g.widthY[c], a, a + 1.0);
        }
        integral[g.axes + i] = v;
    }
}
