#version 450
// One radix-R pass (R = 2, 3 or 4) of a mixed-radix Stockham autosort FFT (Bainville's formulation),
// in double precision, over `count` complex transforms of length n (a product of the passes' radices,
// 2^a 3^b), read from `src` and written to `dst` (ping-pong: after the passes, Ns the product of the
// radices before each, the last `dst` holds the DFT in natural order). Element m of transform t sits
// at t * batch + m * stride, so the same pass runs along rows (stride 1, batch = width) or columns
// (stride = width, batch 1) of a 2-D array. For j < n / R:
//
//   k = j mod Ns,  v_r = src[j + r n / R] exp(-+ 2 pi i r k / (R Ns)),  r = 0 .. R - 1,
//   dst[(j / Ns) R Ns + k + r Ns] = sum_s v_s exp(-+ 2 pi i r s / R)   (the R-point DFT)
//
// (- for the forward transform, + for the inverse, unnormalised). A radix-4 pass does the work of
// two radix-2 passes in one read and one write of the array.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) readonly buffer Src { dvec2 src[]; };
layout(std430, binding = 1) writeonly buffer Dst { dvec2 dst[]; };
// exp(-2 pi i q / n), q < n, for this length, computed on the host in double (GLSL has no double cos
// and sin; float twiddles would leak 1e-7 of a bright light's spectrum over the whole frame).
layout(std430, binding = 2) readonly buffer Twiddles { dvec2 twiddle[]; };

uniform int n;
uniform int radix; // 2, 3 or 4
uniform int ns;
uniform int stride;
uniform int batch;
uniform int count;
uniform int inverse; // 0: forward (exp(-i ...)), 1: inverse (exp(+i ...))
uniform int across;  // 1: invocation x runs across transforms (columns: neighbours read neighbouring memory)

dvec2 mul(dvec2 a, dvec2 b) {
    return dvec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

// exp(-+ 2 pi i q / n) for 0 <= q < n.
dvec2 turn(int q) {
    const dvec2 w = twiddle[q];
    return inverse != 0 ? dvec2(w.x, -w.y) : w;
}

void main() {
    const int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y + gl_GlobalInvocationID.z * gl_NumWorkGroups.y);
    const int j = across != 0 ? y : x, t = across != 0 ? x : y;
    const int m = n / radix;
    if (j >= m || t >= count) return;
    const int base = t * batch;
    const int k = j % ns;
    const int step = m / ns; // exp(-2 pi i r k / (R Ns)) = twiddle[r k n / (R Ns)]
    dvec2 v[4];
    for (int r = 0; r < radix; ++r) {
        v[r] = src[base + (j + r * m) * stride];
        if (r > 0) v[r] = mul(v[r], turn(r * k * step));
    }
    const int i = (j / ns) * radix * ns + k;
    if (radix == 2) {
        dst[base + i * stride] = v[0] + v[1];
        dst[base + (i + ns) * stride] = v[0] - v[1];
    } else if (radix == 4) {
        const dvec2 a0 = v[0] + v[2], a1 = v[0] - v[2], a2 = v[1] + v[3], d = v[1] - v[3];
        // (v1 - v3) times -i (forward) or +i (inverse)
        const dvec2 a3 = inverse != 0 ? dvec2(-d.y, d.x) : dvec2(d.y, -d.x);
        dst[base + i * stride] = a0 + a2;
        dst[base + (i + ns) * stride] = a1 + a3;
        dst[base + (i + 2 * ns) * stride] = a0 - a2;
        dst[base + (i + 3 * ns) * stride] = a1 - a3;
    } else {
        // w = exp(-+ 2 pi i / 3) = -1/2 -+ i sqrt(3)/2: X1, X2 = v0 - (v1 + v2)/2 -+ i (sqrt(3)/2)(v1 - v2)
        const dvec2 s = v[1] + v[2], d = v[1] - v[2], h = v[0] - 0.5 * s;
        const double c = 0.86602540378443864676LF * (inverse != 0 ? -1.0 : 1.0);
        const dvec2 rot = dvec2(c * d.y, -c * d.x); // -i c d
        dst[base + i * stride] = v[0] + s;
        dst[base + (i + ns) * stride] = h + rot;
        dst[base + (i + 2 * ns) * stride] = h - rot;
    }
}
