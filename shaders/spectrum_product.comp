#version 450
// The convolution theorem's product for two real channels transformed together: the transform
// Z = F(r + i g) holds both channels' spectra, R(k) = (Z(k) + conj Z(-k)) / 2 and
// G(k) = (Z(k) - conj Z(-k)) / (2i), and
//
//     Y(k) = (R(k) Kr(k) + i G(k) Kg(k)) x scale,
//
// whose inverse transform is r * kr + i g * kg (both real): the two channels' convolutions in its
// real and imaginary parts. With g = 0 (one channel) Y = Z Kr. In place: each invocation takes k and
// its partner -k (indices mod the period), the one with the smaller index doing both; the inverse
// transform's 1 / (P Q) is folded into scale.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) buffer A { dvec2 a[]; };
layout(std430, binding = 1) readonly buffer Kr { dvec2 kr[]; };
layout(std430, binding = 2) readonly buffer Kg { dvec2 kg[]; };

uniform int period; // P, the row length
uniform int rows;   // Q
uniform double scale;

dvec2 mul(dvec2 x, dvec2 y) {
    return dvec2(x.x * y.x - x.y * y.y, x.x * y.y + x.y * y.x);
}
dvec2 conjugate(dvec2 x) {
    return dvec2(x.x, -x.y);
}

void main() {
    const int i = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (i >= period * rows) return;
    const int x = i % period, y = i / period;
    const int j = ((rows - y) % rows) * period + (period - x) % period;
    if (j < i) return;
    const dvec2 zi = a[i], zj = a[j];
    // R(k) = r and i G(k) = g; at -k, R(-k) = conj r and i G(-k) = -conj g.
    const dvec2 r = (zi + conjugate(zj)) * 0.5LF, g = (zi - conjugate(zj)) * 0.5LF;
    a[i] = (mul(r, kr[i]) + mul(g, kg[i])) * scale;
    if (j != i) a[j] = (mul(conjugate(r), kr[j]) - mul(conjugate(g), kg[j])) * scale;
}
