#version 450
// Compositing the flare onto the plate (docs/simulate.md): composite = plate + flare per colour
// channel, the same single float32 addition as the CPU's image::composite, so the two agree bit for
// bit. Where the flare is exactly zero, or the plate is NaN, the plate's value is passed through
// untouched (no arithmetic), so NaN payloads, -0 and subnormals survive devices that canonicalise or
// flush them. The plate is an RGB float texture;
// the flare three row-major planes; the composite is written R, G, B interleaved, as the EXR writer
// takes it.

layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 0) uniform sampler2D plate;
layout(std430, binding = 1) readonly buffer Flare { float flare[]; };       // [3][H][W]
layout(std430, binding = 2) writeonly buffer Composite { float composite[]; }; // [H][W][3]

uniform int width;
uniform int height;

void main() {
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= width || p.y >= height) return;
    const vec3 base = texelFetch(plate, p, 0).rgb;
    const int index = p.y * width + p.x, plane = width * height;
    for (int c = 0; c < 3; ++c) {
        const float f = flare[c * plane + index];
        composite[3 * index + c] = (f == 0.0 || isnan(base[c])) ? base[c] : base[c] + f;
    }
}
