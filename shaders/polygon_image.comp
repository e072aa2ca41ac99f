#version 450
// Last pass of the binned polygon raster: each pixel's 64-bit fixed-point sum (polygon_tiles.comp)
// as flux per pixel. A negative sum is rounding in the edges' doubles and reads 0 (as
// trace::CoverageRaster does).

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 2) readonly buffer Accumulator { uint acc[]; }; // [channel][row][column] x {low, high}
layout(std430, binding = 3) writeonly buffer Image { float image[]; };   // [channel][row][column]

uniform int pixels; // channels x height x width
uniform double scale;

void main() {
    const int i = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (i >= pixels) return;
    const double v = double(int(acc[2 * i + 1])) * 4294967296.0LF + double(acc[2 * i]);
    image[i] = float(max(v, 0.0) / scale);
}
