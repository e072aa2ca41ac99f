#include "gpu/gl_transfer.h"

#include <algorithm>

namespace ff::gpu {

void uploadCoefficients(const fourier::Coefficients& z, Buffer& buffer) {
    std::vector<float> values;
    values.reserve(3 * z.z[0].size());
    for (const auto& ch : z.z)
        for (double v : ch) values.push_back(static_cast<float>(v));
    buffer.upload(values.data(), values.size() * sizeof(float));
}

void downloadCoefficients(const Buffer& buffer, fourier::Coefficients& z) {
    const std::size_t per = static_cast<std::size_t>(4) * z.n * z.m;
    std::vector<float> values(3 * per);
    buffer.download(values.data(), values.size() * sizeof(float));
    for (std::size_t c = 0; c < 3; ++c)
        z.z[c].assign(values.begin() + static_cast<long>(c * per), values.begin() + static_cast<long>((c + 1) * per));
}

void uploadImage(const fourier::FlareImage& image, Buffer& buffer) {
    std::vector<float> planes;
    planes.reserve(3 * image.pixels());
    for (const auto& ch : image.channel) planes.insert(planes.end(), ch.begin(), ch.end());
    buffer.upload(planes.data(), planes.size() * sizeof(float));
}

void downloadImage(const Buffer& buffer, fourier::FlareImage& image) {
    const std::size_t plane = image.pixels();
    std::vector<float> planes(3 * plane);
    buffer.download(planes.data(), planes.size() * sizeof(float));
    for (std::size_t c = 0; c < 3; ++c)
        std::copy_n(planes.begin() + static_cast<long>(c * plane), plane, image.channel[c].begin());
}

} // namespace ff::gpu
