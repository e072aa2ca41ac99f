// The parts of image/plate.h that need no image library: a plate made from pixels in memory, its
// channels found and its values checked (also for the plates plate.cpp reads), and its RGB.

#include "core/error.h"
#include "image/plate.h"

#include <cmath>
#include <initializer_list>

namespace ff::image {

namespace {

[[noreturn]] void bad(const std::string& path, const std::string& what) {
    throw Error(ErrorKind::Input, SourceLocation{path}, what);
}

} // namespace

std::vector<float> Plate::rgb() const {
    std::vector<float> out(pixelCount() * 3);
    for (std::size_t p = 0; p < pixelCount(); ++p) {
        out[p * 3] = value(p, r);
        out[p * 3 + 1] = value(p, g);
        out[p * 3 + 2] = value(p, b);
    }
    return out;
}

// Finds R, G, B (or a luminance Y) and A among the channel names.
void findChannels(const std::string& path, Plate& p) {
    auto find = [&](std::initializer_list<const char*> names) {
        for (const char* n : names)
            for (std::size_t i = 0; i < p.channels.size(); ++i)
                if (p.channels[i] == n) return static_cast<int>(i);
        return -1;
    };
    p.r = find({"R", "r", "red", "Red"});
    p.g = find({"G", "g", "green", "Green"});
    p.b = find({"B", "b", "blue", "Blue"});
    p.a = find({"A", "a", "alpha", "Alpha"});
    if (p.r >= 0 && p.g >= 0 && p.b >= 0) return;
    const int y = find({"Y", "y"});
    if (y >= 0) {
        p.r = p.g = p.b = y;
        p.notes.push_back("a luminance (Y) plate: lights and the flare are grey");
        return;
    }
    std::string list;
    for (const auto& c : p.channels) list += (list.empty() ? "" : ", ") + c;
    bad(path, "no R, G, B (or Y) channels to find lights in; the channels are: " + list);
}

// A plate with a majority of negative, NaN or infinite pixels is not image data.
void checkValues(const std::string& path, const Plate& p) {
    // A plate is light: mostly finite, non-negative values. A few NaN, infinite or negative pixels are
    // tolerated (and reported by light detection); a majority means the data is not an image.
    std::size_t invalid = 0;
    for (std::size_t i = 0; i < p.pixelCount(); ++i) {
        const float r = p.value(i, p.r), g = p.value(i, p.g), b = p.value(i, p.b);
        invalid += !(std::isfinite(r) && std::isfinite(g) && std::isfinite(b) && r >= 0.0f && g >= 0.0f && b >= 0.0f);
    }
    if (2 * invalid > p.pixelCount())
        bad(path, std::to_string(invalid) + " of " + std::to_string(p.pixelCount()) +
                      " pixels have negative, NaN or infinite colour values: this is not usable image data");
}

Plate plateFromPixels(const std::string& name, int width, int height, std::vector<std::string> channels,
                      std::vector<float> pixels) {
    if (width < 1 || height < 1 || channels.empty() ||
        pixels.size() != static_cast<std::size_t>(width) * height * channels.size())
        bad(name, "the pixels do not fill a " + std::to_string(width) + " x " + std::to_string(height) + " image of " +
                      std::to_string(channels.size()) + " channels");
    Plate p;
    p.path = name;
    p.width = p.displayWidth = width;
    p.height = p.displayHeight = height;
    p.channels = std::move(channels);
    p.pixels = std::move(pixels);
    findChannels(name, p);
    checkValues(name, p);
    return p;
}

} // namespace ff::image
