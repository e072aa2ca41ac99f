#version 450
// First separable pass of the Fourier evaluation (docs/fourier.md, "Accumulation and evaluation"):
//
//     T = Z . Y        per colour channel, T: 2N x H
//
// Z = [[A, B], [C, D]] (2N x 2M) holds the aggregated coefficients; Y (2M x H) the y basis,
// Y[m][j] = kappa_m sinc(m wy / 2) cos(m wy (j + 1/2)) and, in rows M..2M-1, the same with sin
// (the sinc integrates each term over the pixel). One invocation per (row of Z, image row j).
// LOCAL_SIZE is defined by the host from the device's work-group limits.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 0) readonly buffer Coefficients { float z[]; }; // [3][2N][2M]
layout(std430, binding = 1) readonly buffer BasisY { float basisY[]; };  // [2M][H]
layout(std430, binding = 2) writeonly buffer Rows { float t[]; };        // [3][2N][H]

uniform int twoN;
uniform int twoM;
uniform int height;

void main() {
    const int j = int(gl_GlobalInvocationID.x);
    const int row = int(gl_GlobalInvocationID.y); // channel * 2N + n
    if (j >= height || row >= 3 * twoN) return;
    float sum = 0.0;
    const int zRow = row * twoM;
    for (int m = 0; m < twoM; ++m) sum += z[zRow + m] * basisY[m * height + j];
    t[row * height + j] = sum;
}
