#version 450
// The hybrid path's direct drawing, second pass (docs/fourier.md, "Hybrid"; docs/gpu.md): ghosts too
// small for the series, integrated exactly over every pixel of their footprint and added to the image,
//
//     I_c(i, j) += X_c(i) Y_c(j),   X_c(i) = alpha_c Int_{i}^{i+1} p(x - x_k; wx_c) dx,  Y_c likewise,
//
// the axis integrals computed once per ghost by direct_axes.comp (a pixel costs a product per
// overlapping ghost, not four erfc).
//
// Tiled: a 16 x 16 work group per tile of the image. The ghosts are read in chunks of 256; each
// invocation tests one ghost's footprint against the tile, and every invocation of the tile then adds
// the chunk's overlapping ghosts in their given order (the sum does not depend on scheduling).

layout(local_size_x = 16, local_size_y = 16) in;

struct DirectGhost {
    ivec4 box;      // first x, first y, last x, last y (pixels, inclusive), clipped to the frame
    vec2 offset;    // first x - x_k, first y - y_k: the footprint's corner relative to the centre
    float shape;    // 0 Gaussian, 1 cos^2
    int axes;       // index of the ghost's first axis integral (direct_axes.comp)
    vec4 widthX;    // per channel: sigma or half-width w, pixels
    vec4 widthY;
    vec4 peak;      // alpha per channel
};

layout(std430, binding = 0) readonly buffer Ghosts { DirectGhost ghosts[]; };
layout(std430, binding = 1) buffer Image { float image[]; }; // [3][H][W], added to
layout(std430, binding = 2) readonly buffer Integrals { vec4 integral[]; };

uniform int count;
uniform int width;
uniform int height;

const int CHUNK = 256;

shared bool overlaps[CHUNK];

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    const ivec2 tileFirst = ivec2(gl_WorkGroupID.xy) * 16, tileLast = tileFirst + 15;
    const int local = int(gl_LocalInvocationIndex);
    vec3 sum = vec3(0.0);
    for (int base = 0; base < count; base += CHUNK) {
        // Every invocation reaches the barriers, those outside the image included.
        const int k = base + local;
        bool hit = false;
        if (k < count) {
            const ivec4 b = ghosts[k].box;
            hit = b.x <= tileLast.x && b.z >= tileFirst.x && b.y <= tileLast.y && b.w >= tileFirst.y;
        }
        overlaps[local] = hit;
        barrier();
        const int inChunk = min(CHUNK, count - base);
        for (int i = 0; i < inChunk; ++i) {
            if (!overlaps[i]) continue;
            const DirectGhost g = ghosts[base + i];
            if (p.x < g.box.x || p.x > g.box.z || p.y < g.box.y || p.y > g.box.w) continue;
            const int columns = g.box.z - g.box.x + 1;
            sum += integral[g.axes + p.x - g.box.x].xyz * integral[g.axes + columns + p.y - g.box.y].xyz;
        }
        barrier();
    }
    if (p.x >= width || p.y >= height) return;
    const int index = p.y * width + p.x, plane = width * height;
    image[index] += sum.r;
    image[plane + index] += sum.g;
    image[2 * plane + index] += sum.b;
}
