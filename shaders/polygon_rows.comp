#version 450
// Second pass of the polygon raster (polygon_edges.comp): each row's prefix sum of its 64-bit
// fixed-point entries, exactly, turned into flux per pixel. A negative sum is rounding in the edges'
// doubles and reads 0 (as trace::CoverageRaster does).

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 2) readonly buffer Accumulator { uint acc[]; }; // [channel][row][width + 2] x {low, high}
layout(std430, binding = 3) writeonly buffer Image { float image[]; };   // [channel][row][width]

uniform int width;
uniform int rows; // channels x height
uniform double scale;

void main() {
    const int r = int(gl_GlobalInvocationID.x);
    if (r >= rows) return;
    uint lo = 0u, hi = 0u;
    const uint from = 2u * uint(r) * uint(width + 2);
    for (int x = 0; x < width; ++x) {
        const uint a = acc[from + 2u * uint(x)], b = acc[from + 2u * uint(x) + 1u];
        const uint sum = lo + a;
        hi += b + (sum < lo ? 1u : 0u);
        lo = sum;
        const double v = double(int(hi)) * 4294967296.0LF + double(lo);
        image[uint(r) * uint(width) + uint(x)] = float(max(v, 0.0) / scale);
    }
}
