#pragma once
// What the `simulate` CLI tests share: small generated plates, EXRs read back, the command line.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "test_support.h"

namespace ff::test::simulate {

namespace fs = std::filesystem;

// Ghost tables are cached across the tests of this suite (the cache is keyed and written atomically).
inline const std::string kEnv = std::string("FF_CACHE_DIR='") + FF_TEST_CACHE_DIR + "' ";
inline const std::string kLens = "lenses/cooke-triplet-50mm-f5.lens";
constexpr int kW = 96, kH = 64;

struct TestPlate {
    std::vector<float> rgba = std::vector<float>(static_cast<std::size_t>(kW) * kH * 4, 0.0f);
    std::vector<float> z = std::vector<float>(static_cast<std::size_t>(kW) * kH, 0.0f);
    void set(int x, int y, float r, float g, float b, float a = 1.0f) {
        float* p = &rgba[(static_cast<std::size_t>(y) * kW + x) * 4];
        p[0] = r, p[1] = g, p[2] = b, p[3] = a;
    }
};

// A plate with half R, G, B, A and a float Z, a faint background, a custom attribute; the data
// window may be offset inside the display window (of the data window's size plus margin on each
// side, by default the offset).
inline TestPlate writePlate(const fs::path& path, int lightX, int lightY, float value, int originX = 0, int originY = 0,
                            int marginX = -1, int marginY = -1) {
    TestPlate t;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            t.set(x, y, 0.02f + 0.001f * float(x), 0.03f, 0.04f + 0.001f * float(y), 0.5f);
            t.z[static_cast<std::size_t>(y) * kW + x] = 10.0f + float(x) + 0.25f * float(y);
        }
    if (lightX >= 0)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) t.set(lightX + dx, lightY + dy, value, value, value);
    OIIO::ImageSpec spec(kW, kH, 5, OIIO::TypeDesc::HALF);
    spec.channelnames = {"R", "G", "B", "A", "Z"};
    spec.channelformats = {OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF,
                           OIIO::TypeDesc::FLOAT};
    spec.alpha_channel = 3;
    spec.z_channel = 4;
    spec.x = originX;
    spec.y = originY;
    spec.full_x = 0;
    spec.full_y = 0;
    spec.full_width = kW + originX + (marginX < 0 ? originX : marginX);
    spec.full_height = kH + originY + (marginY < 0 ? originY : marginY);
    spec.attribute("compression", "zip");
    spec.attribute("studio:shot", "sq010_sh020");
    std::vector<float> all(static_cast<std::size_t>(kW) * kH * 5);
    for (std::size_t p = 0; p < static_cast<std::size_t>(kW) * kH; ++p) {
        for (int c = 0; c < 4; ++c) all[p * 5 + c] = t.rgba[p * 4 + c];
        all[p * 5 + 4] = t.z[p];
    }
    auto out = OIIO::ImageOutput::create(path.string());
    EXPECT_TRUE(out && out->open(path.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, all.data()) &&
                out->close());
    return t;
}

struct Exr {
    OIIO::ImageSpec spec;
    std::vector<float> pixels; // all channels as float
    int channel(const std::string& name) const {
        for (int i = 0; i < spec.nchannels; ++i)
            if (spec.channelnames[static_cast<std::size_t>(i)] == name) return i;
        return -1;
    }
    float at(std::size_t p, int c) const {
        return pixels[p * static_cast<std::size_t>(spec.nchannels) + static_cast<std::size_t>(c)];
    }
};

inline Exr readExr(const fs::path& path) {
    Exr e;
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return e;
    e.spec = in->spec();
    e.pixels.resize(static_cast<std::size_t>(e.spec.width) * e.spec.height * e.spec.nchannels);
    in->read_image(0, 0, 0, e.spec.nchannels, OIIO::TypeDesc::FLOAT, e.pixels.data());
    return e;
}

inline std::string simulate(const fs::path& plate, const fs::path& out, const std::string& extra = "") {
    return "simulate --lens " + kLens + " --plate '" + plate.string() + "' -o '" + out.string() + "' " + extra;
}

} // namespace ff::test::simulate
