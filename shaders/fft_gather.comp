#version 450
// The frame's pixels of the inverse transform (the period is `period` wide), complex: the two
// channels' convolutions in the real and imaginary parts (width x height, row-major).

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) readonly buffer A { dvec2 a[]; };
layout(std430, binding = 1) writeonly buffer Out { dvec2 frame[]; };

uniform int width;
uniform int period;
uniform int count; // width x height

void main() {
    const int i = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (i >= count) return;
    frame[i] = a[(i / width) * period + i % width];
}
