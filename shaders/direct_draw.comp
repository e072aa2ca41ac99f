#version 450
// The hybrid path's direct drawing (docs/fourier.md, "Hybrid"): ghosts too small for the series are
// integrated exactly over every pixel of their footprint and added to the image,
//
//     I_c(i, j) += alpha_c  Int_{i}^{i+1} p(x - x_k; wx_c) dx  Int_{j}^{j+1} p(y - y_k; wy_c) dy,
//
// with p the unit-peak profile. Pixel integrals of the Gaussian exp(-u^2 / 2 s^2):
// s sqrt(pi / 2) [erf(b / s sqrt 2) - erf(a / s sqrt 2)], written with erfc on one side of the centre
// so that tail pixels keep their relative precision (erfc from Abramowitz & Stegun 7.1.26, absolute
// error 1.5e-7; the GPU has no erf). Of cos^2(pi u / 2w) on |u| < w: F(b) - F(a),
// F(u) = u / 2 + (w / 2 pi) sin(pi u / w) with u clamped to the support.
//
// Tiled: a 16 x 16 work group per tile of the image. The ghosts are read in chunks of 256; each
// invocation tests one ghost's footprint against the tile, and every invocation of the tile then adds
// the chunk's overlapping ghosts in their given order (the sum does not depend on scheduling).

layout(local_size_x = 16, local_size_y = 16) in;

struct DirectGhost {
    ivec4 box;      // first x, first y, last x, last y (pixels, inclusive), clipped to the frame
    vec2 offset;    // first x - x_k, first y - y_k: the footprint's corner relative to the centre
    float shape;    // 0 Gaussian, 1 cos^2
    float pad;
    vec4 widthX;    // per channel: sigma or half-width w, pixels
    vec4 widthY;
    vec4 peak;      // alpha per channel
};

layout(std430, binding = 0) readonly buffer Ghosts { DirectGhost ghosts[]; };
layout(std430, binding = 1) buffer Image { float image[]; }; // [3][H][W], added to

uniform int count;
uniform int width;
uniform int height;

const float PI = 3.14159265358979;
const int CHUNK = 256;

shared bool overlaps[CHUNK];

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
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    const ivec2 tileFirst = ivec2(gl_WorkGroupID.xy) * 16, tileLast = tileFirst + 15;
    const int local = int(gl_LocalInvocationIndex);
    vec3 sum = vec3(0.0);
    for (int base = 0; base < count; base += CHUNK) {
        // Every invocation reaches the barriers, those outside the image included.
        const int k = base + local;
        bool hit = false;
        if (k < count) {
            const ivec4 b = ghosts[k].box;
            hit = b.x <= tileLast.x && b.z >= tileFirst.x && b.y <= tileLast.y && b.w >= tileFirst.y;
        }
        overlaps[local] = hit;
        barrier();
        const int inChunk = min(CHUNK, count - base);
        for (int i = 0; i < inChunk; ++i) {
            if (!overlaps[i]) continue;
            const DirectGhost g = ghosts[base + i];
            if (p.x < g.box.x || p.x > g.box.z || p.y < g.box.y || p.y > g.box.w) continue;
            const float ax = g.offset.x + float(p.x - g.box.x), ay = g.offset.y + float(p.y - g.box.y);
            for (int c = 0; c < 3; ++c)
                sum[c] += g.peak[c] * cellIntegral(g.shape, g.widthX[c], ax, ax + 1.0) * cellIntegral(g.shape, g.widthY[c], ay, ay + 1.0);
        }
        barrier();
    }
    if (p.x >= width || p.y >= height) return;
    const int index = p.y * width + p.x, plane = width * height;
    image[index] += sum.r;
    image[plane + index] += sum.g;
    image[2 * plane + index] += sum.b;
}
