#version 450
// One radix-2 pass of a Stockham autosort FFT (Bainville's formulation), in double precision, over
// `count` complex transforms of length n (a power of 2), read from `src` and written to `dst`
// (ping-pong: after log2(n) passes with Ns = 1, 2, 4, ..., n / 2 the last `dst` holds the DFT in
// natural order). Element m of transform t sits at t * batch + m * stride, so the same pass runs
// along rows (stride 1, batch = width) or columns (stride = width, batch 1) of a 2-D array.
//
//   k = j mod Ns,  v1 *= exp(-+ 2 pi i k / (2 Ns)),
//   dst[(j / Ns) 2 Ns + k] = v0 + v1,  dst[(j / Ns) 2 Ns + k + Ns] = v0 - v1,   v0 = src[j], v1 = src[j + n / 2]
//
// (- for the forward transform, + for the inverse, unnormalised).

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) readonly buffer Src { dvec2 src[]; };
layout(std430, binding = 1) writeonly buffer Dst { dvec2 dst[]; };
// exp(-2 pi i q / L), q < L / 2, computed on the host in double (GLSL has no double cos and sin;
// float twiddles would leak 1e-7 of a bright light's spectrum over the whole frame).
layout(std430, binding = 2) readonly buffer Twiddles { dvec2 twiddle[]; };

uniform int n;
uniform int ns;
uniform int stride;
uniform int batch;
uniform int count;
uniform int inverse; // 0: forward (exp(-i ...)), 1: inverse (exp(+i ...))
uniform int step;    // L / (2 ns): twiddle q = k * step
uniform int across;  // 1: invocation x runs across transforms (columns: neighbours read neighbouring memory)

void main() {
    const int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y + gl_GlobalInvocationID.z * gl_NumWorkGroups.y);
    const int j = across != 0 ? y : x, t = across != 0 ? x : y;
    if (j >= n / 2 || t >= count) return;
    const int base = t * batch;
    const dvec2 v0 = src[base + j * stride];
    dvec2 v1 = src[base + (j + n / 2) * stride];
    const int k = j & (ns - 1);
    dvec2 w = twiddle[k * step];
    if (inverse != 0) w.y = -w.y;
    v1 = dvec2(v1.x * w.x - v1.y * w.y, v1.x * w.y + v1.y * w.x);
    const int i = (j / ns) * 2 * ns + k;
    dst[base + i * stride] = v0 + v1;
    dst[base + (i + ns) * stride] = v0 - v1;
}
