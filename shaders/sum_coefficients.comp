#version 450
// Adds per-ghost coefficient slices into Z: Z[e] += sum_k slices[k][e], one invocation per entry e of
// Z = [3][2N][2M], the ghosts in order (a deterministic sum; no float atomics in OpenGL 4.5).

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) readonly buffer Slices { float slices[]; };
layout(std430, binding = 1) buffer Coefficients { float z[]; };

uniform int count;   // slices
uniform int entries; // 3 * 2N * 2M

void main() {
    const int e = int(gl_GlobalInvocationID.x);
    if (e >= entries) return;
    float sum = z[e];
    for (int k = 0; k < count; ++k) sum += slices[k * entries + e];
    z[e] = sum;
}
