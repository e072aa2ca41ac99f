#version 450
// Fourier coefficients of sampled profiles (docs/fourier.md, "Sampled profiles"; CPU twin:
// src/fourier/sampled.cpp). A ghost is a grid of cells of size s holding the flux that falls on each,
// P_ij, with centres x_i = x0 + (i + 1/2) s, y_j likewise; its coefficients are the midpoint sums with
// the cell's box divided out:
//
//     A_nm = sum_j (sum_i P_ij cos(n wx x_i)) cos(m wy y_j) / (Tx Ty sinc(n wx s / 2) sinc(m wy s / 2))
//
// (B: cos . sin, C: sin . cos, D: sin . sin). One work group per ghost, one invocation per term (n, m)
// (strided when N M exceeds the work group), all three channels at once; each writes its ghost's
// slice of the output, and sum_coefficients.comp adds the slices into Z in ghost order. Phases are
// 2 pi fract(n u) with u the cell centre as a fraction of the period (reduced in double on the host).

layout(local_size_x = LOCAL_SIZE) in;

struct SampledGhost {
    vec2 first;   // centre of cell (0, 0) / period, in [0, 1)
    vec2 step;    // cell size / period
    ivec2 size;   // cells
    int offset;   // index of its first value in `values` (R, G, B interleaved, rows of size.x)
    int pad;
};

layout(std430, binding = 0) readonly buffer Ghosts { SampledGhost ghosts[]; };
layout(std430, binding = 1) readonly buffer Values { float values[]; };
layout(std430, binding = 2) writeonly buffer Slices { float slices[]; }; // [ghost][3][2N][2M]

uniform int first;  // the chunk's first ghost
uniform int N;
uniform int M;
uniform float periodX;
uniform float periodY;

const float PI = 3.14159265358979;

// sin(u) / u. Below |u| = 1 by its Taylor series, whose first term left out (u^10 / 11!) is under
// 2.6e-8: a GPU's sin is good to an absolute error of about 5e-7 (NVIDIA's), a relative error of
// 5e-7 / u near 0, which the 1 / sinc of a low term would carry into the coefficient.
float sinc(float u) {
    const float u2 = u * u;
    if (u2 < 1.0) return 1.0 + u2 * (-1.0 / 6.0 + u2 * (1.0 / 120.0 + u2 * (-1.0 / 5040.0 + u2 / 362880.0)));
    return sin(u) / u;
}

void main() {
    const int local = int(gl_WorkGroupID.x);
    const SampledGhost g = ghosts[first + local];
    const int terms = N * M, slice = 3 * 4 * terms;
    for (int t = int(gl_LocalInvocationID.x); t < terms; t += LOCAL_SIZE) {
        const int n = t / M, m = t % M;
        vec3 a = vec3(0.0), b = vec3(0.0), c = vec3(0.0), d = vec3(0.0);
        for (int j = 0; j < g.size.y; ++j) {
            const float py = 2.0 * PI * fract(float(m) * g.first.y + fract(float(m) * g.step.y) * float(j));
            vec3 rc = vec3(0.0), rs = vec3(0.0);
            for (int i = 0; i < g.size.x; ++i) {
                const float px = 2.0 * PI * fract(float(n) * g.first.x + fract(float(n) * g.step.x) * float(i));
                const int v = g.offset + 3 * (j * g.size.x + i);
                const vec3 p = vec3(values[v], values[v + 1], values[v + 2]);
                rc += p * cos(px);
                rs += p * sin(px);
            }
            const float cy = cos(py), sy = sin(py);
            a += rc * cy;
            b += rc * sy;
            c += rs * cy;
            d += rs * sy;
        }
        // wx s / 2 = pi s / Tx.
        const float scale = 1.0 / (periodX * periodY * sinc(PI * float(n) * g.step.x) * sinc(PI * float(m) * g.step.y));
        for (int ch = 0; ch < 3; ++ch) {
            const int base = local * slice + ch * 4 * terms;
            slices[base + n * (2 * M) + m] = scale * a[ch];
            slices[base + n * (2 * M) + M + m] = scale * b[ch];
            slices[base + (N + n) * (2 * M) + m] = scale * c[ch];
            slices[base + (N + n) * (2 * M) + M + m] = scale * d[ch];
        }
    }
}
