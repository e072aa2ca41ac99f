#pragma once
// Coefficients and images between the CPU's types and the layouts the shaders use.

#include "fourier/aggregate.h"
#include "gpu/gl_objects.h"

namespace ff::gpu {

/// Z as float [3][2n][2m] (the CPU's double values rounded).
void uploadCoefficients(const fourier::Coefficients& z, Buffer& buffer);
/// Reads float [3][2n][2m] back into z (its n and m say the size).
void downloadCoefficients(const Buffer& buffer, fourier::Coefficients& z);
/// An image as three row-major float planes, [3][height][width].
void uploadImage(const fourier::FlareImage& image, Buffer& buffer);
/// Reads [3][height][width] back into image (its size says the size).
void downloadImage(const Buffer& buffer, fourier::FlareImage& image);

} // namespace ff::gpu
