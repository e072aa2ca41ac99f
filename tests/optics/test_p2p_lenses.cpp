// Real FlareSim-family lens files converted from patent data (../shared/data/lenses-p2p, not part
// of the repository). Each must parse, or fail with a message that names file:line; the computed
// EFL is printed beside the header's nominal focal_length.

#include "core/error.h"
#include "core/units.h"
#include "optics/lens_loader.h"
#include "optics/paraxial.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "test_support.h"

using namespace ff;
using namespace ff::optics;

TEST(P2pLenses, EveryFileParsesOrFailsPrecisely) {
    const auto dir = test::sharedDataDir() / "lenses-p2p";
    if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "shared data folder absent: " << dir;
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".lens") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    ASSERT_FALSE(files.empty());

    int parsed = 0, beyond2 = 0;
    std::printf("%-80s %10s %10s %8s\n", "file", "header f", "EFL", "diff");
    for (const auto& f : files) {
        try {
            const Lens lens = loadLens(f);
            const double efl = paraxialEfl(lens, lines::d);
            ++parsed;
            if (lens.nominalFocalLength) {
                const double diff = (efl - *lens.nominalFocalLength) / *lens.nominalFocalLength;
                beyond2 += std::abs(diff) > 0.02;
                std::printf("%-80s %10.2f %10.3f %+7.2f%%%s\n", f.filename().c_str(), *lens.nominalFocalLength, efl,
                            100.0 * diff, std::abs(diff) > 0.02 ? "  (> 2 %)" : "");
            } else {
                std::printf("%-80s %10s %10.3f\n", f.filename().c_str(), "-", efl);
            }
        } catch (const Error& e) {
            std::printf("%-80s error: %s\n", f.filename().c_str(), e.what());
            EXPECT_GT(e.where().line, 0) << "error without a line: " << e.what();
            EXPECT_NE(std::string(e.what()).find(f.filename().string()), std::string::npos) << e.what();
        }
    }
    std::printf("%d of %zu files parsed; %d differ from their header focal length by more than 2 %%\n", parsed,
                files.size(), beyond2);
}
