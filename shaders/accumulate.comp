#version 450
// Accumulation of the separable Fourier coefficients (docs/fourier.md):
//
//     A_nm = sum_k alpha_k g_n^k h_m^k cos(n wx x_k) cos(m wy y_k)     B_nm: cos . sin
//     C_nm = sum_k alpha_k g_n^k h_m^k sin(n wx x_k) cos(m wy y_k)     D_nm: sin . sin
//
// One invocation per (n, m) and channel, looping over the ghosts (the "thread per (n, m)" layout). The
// profiles' coefficients are the closed forms without erf: the periodised Gaussian
// g_n = (sigma sqrt(2 pi) / T) exp(-(n w sigma)^2 / 2), or the cos^2 bump's Hann form
// h_n = (w / T) [S(t) + S(t - pi)/2 + S(t + pi)/2], t = n w half-width, S(u) = sin(u) / u.
// Phases: the host passes each centre as a fraction of its period (in double, reduced to [0, 1)), so
// the shader's float argument 2 pi fract(n u) stays small. Output: Z[c][2N][2M] = [[A, B], [C, D]].

layout(local_size_x = LOCAL_SIZE) in;

struct Ghost {
    float u, v;          // centre / period, in [0, 1)
    float shape;         // 0 Gaussian, 1 cos^2
    float pad;
    vec4 widthX;         // per channel, pixels (w unused)
    vec4 widthY;
    vec4 peak;           // alpha per channel
};

layout(std430, binding = 0) readonly buffer Ghosts { Ghost ghosts[]; };
layout(std430, binding = 1) writeonly buffer Coefficients { float z[]; }; // [3][2N][2M]

uniform int count;
uniform int N;
uniform int M;
uniform float periodX;
uniform float periodY;
uniform int dropDc;     // 1: A_00 = 0 (--drop-dc)

const float PI = 3.14159265358979;

// sin(u) / u. Below |u| = 1 by its Taylor series, whose first term left out (u^10 / 11!) is under
// 2.6e-8: a GPU's sin is good to an absolute error of about 5e-7 (NVIDIA's), a relative error of
// 5e-7 / u near 0, which the 1 / sinc of a low term would carry into the coefficient.
float sinc(float u) {
    const float u2 = u * u;
    if (u2 < 1.0) return 1.0 + u2 * (-1.0 / 6.0 + u2 * (1.0 / 120.0 + u2 * (-1.0 / 5040.0 + u2 / 362880.0)));
    return sin(u) / u;
}

float profile(float shape, int n, float width, float period) {
    const float w = 2.0 * PI / period;
    if (shape < 0.5) {
        const float b = float(n) * w * width;
        return width * sqrt(2.0 * PI) / period * exp(-0.5 * b * b);
    }
    const float t = float(n) * w * width;
    return width / period * (sinc(t) + 0.5 * sinc(t - PI) + 0.5 * sinc(t + PI));
}

void main() {
    const int index = int(gl_GlobalInvocationID.x); // (c * N + n) * M + m
    if (index >= 3 * N * M) return;
    const int m = index % M, n = (index / M) % N, c = index / (N * M);
    float a = 0.0, b = 0.0, cc = 0.0, d = 0.0;
    for (int k = 0; k < count; ++k) {
        const Ghost g = ghosts[k];
        const float gx = profile(g.shape, n, g.widthX[c], periodX), hy = profile(g.shape, m, g.widthY[c], periodY);
        const float amplitude = g.peak[c] * gx * hy;
        const float px = 2.0 * PI * fract(float(n) * g.u), py = 2.0 * PI * fract(float(m) * g.v);
        const float cx = cos(px), sx = sin(px), cy = cos(py), sy = sin(py);
        a += amplitude * cx * cy;
        b += amplitude * cx * sy;
        cc += amplitude * sx * cy;
        d += amplitude * sx * sy;
    }
    if (dropDc != 0 && n == 0 && m == 0) a = 0.0;
    const int base = c * (2 * N) * (2 * M);
    z[base + n * (2 * M) + m] = a;
    z[base + n * (2 * M) + M + m] = b;
    z[base + (N + n) * (2 * M) + m] = cc;
    z[base + (N + n) * (2 * M) + M + m] = d;
}
