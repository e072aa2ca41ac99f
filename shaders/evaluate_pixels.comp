#version 450
// Second separable pass of the Fourier evaluation (docs/fourier.md):
//
//     I(x_i, y_j) = sum_n T[n][j] X[n][i]      per colour channel
//
// with X (2N x W) the x basis, X[n][i] = kappa_n sinc(n wx / 2) cos(n wx (i + 1/2)) and, in rows
// N..2N-1, the same with sin. One invocation per pixel, all three channels; the result is added to
// the image (three row-major planes), which may already hold another level or be zero.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) readonly buffer Rows { float t[]; };        // [3][2N][H]
layout(std430, binding = 1) readonly buffer BasisX { float basisX[]; }; // [2N][W]
layout(std430, binding = 2) buffer Image { float image[]; };            // [3][H][W]

uniform int twoN;
uniform int width;
uniform int height;

void main() {
    const int i = int(gl_GlobalInvocationID.x);
    const int j = int(gl_GlobalInvocationID.y);
    if (i >= width || j >= height) return;
    vec3 sum = vec3(0.0);
    for (int n = 0; n < twoN; ++n) {
        const float x = basisX[n * width + i];
        sum += x * vec3(t[n * height + j], t[(twoN + n) * height + j], t[(2 * twoN + n) * height + j]);
    }
    const int p = j * width + i, plane = width * height;
    image[p] += sum.r;
    image[plane + p] += sum.g;
    image[2 * plane + p] += sum.b;
}
