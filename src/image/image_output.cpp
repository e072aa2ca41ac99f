#include "image/image_output.h"

#include "core/error.h"
#include "image/atomic_write.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

namespace ff::image {

void setExrThreads(int n) {
    OIIO::attribute("exr_threads", std::max(n, 1));
}

void writeExr(const std::string& path, int width, int height, const std::vector<std::string>& channels,
              const std::vector<float>& pixels, const Metadata& metadata) {
    if (pixels.size() != static_cast<std::size_t>(width) * height * channels.size())
        throwRuntimeError("writeExr: pixel buffer does not match " + std::to_string(width) + "x" +
                          std::to_string(height));
    OIIO::ImageSpec spec(width, height, static_cast<int>(channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = channels;
    spec.attribute("compression", "zip");
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    writeAtomic(path, spec, OIIO::TypeDesc::FLOAT, pixels.data());
}

std::vector<unsigned char> tonemapPreview(const std::vector<float>& rgb, double exposureEv) {
    const double scale = std::exp2(exposureEv);
    std::vector<unsigned char> out(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        const double v = std::max(0.0, static_cast<double>(rgb[i]) * scale);
        const double t = v / (1.0 + v);
        const double s = t <= 0.0031308 ? 12.92 * t : 1.055 * std::pow(t, 1.0 / 2.4) - 0.055;
        out[i] = static_cast<unsigned char>(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
    }
    return out;
}

double autoExposure(const std::vector<float>& rgb) {
    std::vector<float> peaks;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
        const float m = std::max({rgb[i], rgb[i + 1], rgb[i + 2]});
        if (m > 0.0f && std::isfinite(m)) peaks.push_back(m);
    }
    if (peaks.empty()) return 0.0;
    const std::size_t k =
        std::min(peaks.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(peaks.size())));
    std::nth_element(peaks.begin(), peaks.begin() + static_cast<long>(k), peaks.end());
    return -std::log2(static_cast<double>(peaks[k]));
}

void writePng(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb8,
              const Metadata& metadata) {
    if (rgb8.size() != static_cast<std::size_t>(width) * height * 3)
        throwRuntimeError("writePng: pixel buffer size mismatch");
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    writeAtomic(path, spec, OIIO::TypeDesc::UINT8, rgb8.data());
}

} // namespace ff::image
