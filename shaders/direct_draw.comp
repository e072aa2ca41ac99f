#version 450
// The hybrid path's direct drawing, second pass (docs/fourier.md, "Hybrid"; docs/gpu.md): ghosts too
// small for the series, integrated exactly over every pixel of their footprint and added to the image,
//
//     I_c(i, j) += X_c(i) Y_c(j),   X_c(i) = alpha_c Int_{i}^{i+1} p(x - x_k; wx_c) dx,  Y_c likewise,
//
// the axis integrals computed once per ghost by direct_axes.comp (a pixel costs a product per
// overlapping ghost, not four erfc).
//
// Tiled: a 16 x 16 work group per tile of the image. The host bins the ghosts by tile (a ghost is
// listed in every tile its footprint touches, in the given order), so a tile visits only the ghosts
// that reach it, and each pixel adds them in order (the sum does not depend on scheduling).

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

layout(std430, binding = 3) readonly buffer TileStart { int tileStart[]; };   // per tile, + 1 at the end
layout(std430, binding = 4) readonly buffer TileGhosts { int tileGhosts[]; }; // ghost indices, tile by tile

uniform int width;
uniform int height;
uniform int tilesX;

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= width || p.y >= height) return;
    const int tile = int(gl_WorkGroupID.y) * tilesX + int(gl_WorkGroupID.x);
    vec3 sum = vec3(0.0);
    for (int e = tileStart[tile]; e < tileStart[tile + 1]; ++e) {
        const int k = tileGhosts[e];
        const ivec4 b = ghosts[k].box;
        if (p.x < b.x || p.x > b.z || p.y < b.y || p.y > b.w) continue;
        const int axes = ghosts[k].axes;
        sum += integral[axes + p.x - b.x].xyz * integral[axes + (b.z - b.x + 1) + p.y - b.y].xyz;
    }
    const int index = p.y * width + p.x, plane = width * height;
    image[index] += sum.r;
    image[plane + index] += sum.g;
    image[2 * plane + index] += sum.b;
}
