#pragma once
// The plates the simulate benches draw: 1920 x 1080, a 0.05 grey with `lights` 3 x 3-pixel lights of
// 500 at seeded places (the same places for every bench and run).

#include <cstddef>
#include <random>
#include <vector>

namespace ff::bench {

constexpr int kPlateWidth = 1920, kPlateHeight = 1080;

/// R, G, B interleaved, rows top to bottom.
inline std::vector<float> platePixels(int lights) {
    std::vector<float> px(static_cast<std::size_t>(kPlateWidth) * kPlateHeight * 3, 0.05f);
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> x(10, kPlateWidth - 12), y(10, kPlateHeight - 12);
    for (int l = 0; l < lights; ++l) {
        const int cx = x(rng), cy = y(rng);
        for (int dy = 0; dy < 3; ++dy)
            for (int dx = 0; dx < 3; ++dx)
                for (int c = 0; c < 3; ++c)
                    px[(static_cast<std::size_t>(cy + dy) * kPlateWidth + cx + dx) * 3 + c] = 500.0f;
    }
    return px;
}

} // namespace ff::bench
