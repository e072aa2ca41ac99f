#version 450
// Second pass of the polygon raster (polygon_edges.comp): each row's prefix sum of its 64-bit
// fixed-point entries, exactly (with a linear density's slopes summed twice), turned into flux per
// pixel. A negative sum is rounding in the edges'
// doubles and reads 0 (as trace::CoverageRaster does).

layout(local_size_x = LOCAL_SIZE) in;

// [part][channel][row][width + 2] x {low, high}: the entries, then the slopes (polygon_edges.comp).
layout(std430, binding = 2) readonly buffer Accumulator { uint acc[]; };
layout(std430, binding = 3) writeonly buffer Image { float image[]; };   // [channel][row][width]

uniform int width;
uniform int rows; // channels x height
uniform double scale;

uvec2 add64(uvec2 a, uvec2 b) {
    const uint lo = a.x + b.x;
    return uvec2(lo, a.y + b.y + (lo < a.x ? 1u : 0u));
}

void main() {
    const int r = int(gl_GlobalInvocationID.x);
    if (r >= rows) return;
    // The entries' running sum, the slopes' running sum and the ramp (the slopes' sum summed again),
    // each as {low, high} words modulo 2^64.
    uvec2 sum = uvec2(0u), slope = uvec2(0u), ramp = uvec2(0u);
    const uint from = 2u * uint(r) * uint(width + 2), slopes = 2u * uint(rows) * uint(width + 2);
    for (int x = 0; x < width; ++x) {
        const uint i = from + 2u * uint(x);
        sum = add64(sum, uvec2(acc[i], acc[i + 1u]));
        ramp = add64(ramp, slope);
        slope = add64(slope, uvec2(acc[slopes + i], acc[slopes + i + 1u]));
        const uvec2 total = add64(sum, ramp);
        const double v = double(int(total.y)) * 4294967296.0LF + double(total.x);
        image[uint(r) * uint(width) + uint(x)] = float(max(v, 0.0) / scale);
    }
}
