#version 450
// a[i] = a[i] x b[i] x scale over complex double arrays: the convolution theorem's product of the
// image's and the kernel's spectra, with the inverse transform's 1 / (P Q) folded in.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) buffer A { dvec2 a[]; };
layout(std430, binding = 1) readonly buffer B { dvec2 b[]; };

uniform int count;
uniform double scale;

void main() {
    const int i = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (i >= count) return;
    const dvec2 x = a[i], y = b[i];
    a[i] = dvec2(x.x * y.x - x.y * y.y, x.x * y.y + x.y * y.x) * scale;
}
