#include "fourier/ghost.h"

#include <algorithm>
#include <cmath>

namespace ff::fourier {

namespace {

// exp(-u^2 / 2 sigma^2) = 1e-8 at u = sigma sqrt(2 ln 1e8).
const double kGaussianExtent = std::sqrt(2.0 * std::log(1e8));

double extent(Shape s, const std::array<double, 3>& w) {
    return s == Shape::Gaussian ? kGaussianExtent * widest(w) : widest(w);
}

} // namespace

double Ghost::extentX() const {
    return extent(shape, widthX);
}
double Ghost::extentY() const {
    return extent(shape, widthY);
}

FlareImage::FlareImage(int w, int h) : width(w), height(h) {
    for (auto& c : channel) c.assign(pixels(), 0.0f);
}

std::vector<float> FlareImage::interleaved() const {
    std::vector<float> out(pixels() * 3);
    for (std::size_t p = 0; p < pixels(); ++p)
        for (int c = 0; c < 3; ++c) out[p * 3 + c] = channel[c][p];
    return out;
}

double FlareImage::sum(int c) const {
    double s = 0.0;
    for (float v : channel[c]) s += v;
    return s;
}

} // namespace ff::fourier
