#version 450
// Two channels of the lights' image (width x height, R, G, B interleaved floats) laid into the
// convolution's complex double period (period x rows, row-major) as r + i g (second < 0: g = 0):
// at the frame's pixels, zero elsewhere (the padding that keeps the linear convolution's wrap-around
// out of the frame). Only the frame's rows are written: the transform zeroes the rest.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) writeonly buffer A { dvec2 a[]; };
layout(std430, binding = 1) readonly buffer Image { float image[]; };

uniform int width;
uniform int period;
uniform int count; // period x height
uniform int first;
uniform int second;

void main() {
    const int i = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (i >= count) return;
    const int x = i % period, y = i / period;
    dvec2 v = dvec2(0.0LF);
    if (x < width) {
        const int p = (y * width + x) * 3;
        v = dvec2(double(image[p + first]), second < 0 ? 0.0LF : double(image[p + second]));
    }
    a[i] = v;
}
