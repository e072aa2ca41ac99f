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
              const std::vector<float>& pixels, const Metadata& metadata, double pixelAspectRatio) {
    if (pixels.size() != static_cast<std::size_t>(width) * height * channels.size())
        throwRuntimeError("writeExr: pixel buffer does not match " + std::to_string(width) + "x" +
                          std::to_string(height));
    OIIO::ImageSpec spec(width, height, static_cast<int>(channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = channels;
    spec.attribute("compression", "zip");
    if (pixelAspectRatio != 1.0) spec.attribute("PixelAspectRatio", static_cast<float>(pixelAspectRatio));
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    writeAtomic(path, spec, OIIO::TypeDesc::FLOAT, pixels.data());
}

std::vector<float> stretchedRows(const std::vector<float>& rgb, int width, int height, double factor, int* outWidth) {
    if (!(factor > 0.0) || !std::isfinite(factor) || width < 1 || height < 0 ||
        rgb.size() != static_cast<std::size_t>(width) * height * 3)
        throwRuntimeError("stretchedRows: the image or the factor is not valid");
    const int W = std::max(1, static_cast<int>(std::lround(width * factor)));
    std::vector<float> out(static_cast<std::size_t>(W) * height * 3);
    for (int i = 0; i < W; ++i) {
        // Output centre i + 0.5 at input x = (i + 0.5) width / W; between input centres j + 0.5, j + 1.5.
        const double x = (i + 0.5) * width / W - 0.5;
        const int j0 = std::clamp(static_cast<int>(std::floor(x)), 0, width - 1), j1 = std::min(j0 + 1, width - 1);
        const double t = std::clamp(x - j0, 0.0, 1.0);
        for (int y = 0; y < height; ++y)
            for (int c = 0; c < 3; ++c) {
                const std::size_t row = static_cast<std::size_t>(y) * width;
                out[(static_cast<std::size_t>(y) * W + i) * 3 + c] =
                    static_cast<float>((1.0 - t) * rgb[(row + j0) * 3 + c] + t * rgb[(row + j1) * 3 + c]);
            }
    }
    if (outWidth) *outWidth = W;
    return out;
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
