#include "core/error.h"
#include "core/file_io.h"
#include "ghosts/ghost_table.h"
#include "ghosts/shaped_cache.h"
#include "optics/lens_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "test_support.h"

using namespace ff;
using namespace ff::ghosts;

namespace {

const optics::Lens& cooke() {
    static const optics::Lens lens =
        optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens");
    return lens;
}

TableSettings small() {
    TableSettings s;
    s.grid = 16;
    s.angles = 5;
    return s;
}

std::size_t lostValues(const ShapedTable& t) {
    std::size_t n = 0;
    for (const auto& g : t.ghosts)
        for (const auto& perAngle : g.meshes)
            for (const auto& m : perAngle)
                for (float v : m.data) n += std::isnan(v);
    return n;
}

} // namespace

// The stored table gives back the layout and fluxes exactly and every mesh value within half a step
// of 16-bit quantisation over that attribute's range in the ghost's meshes at that wavelength,
// (max - min) / 65534 / 2 (float rounding aside); a lost ray's values stay lost.
TEST(ShapedCache, RoundTripKeepsEveryValueWithinHalfAQuantisationStep) {
    const ShapedTable t = buildShapedTable(cooke(), small());
    ASSERT_GT(lostValues(t), 0u); // the Cooke triplet vignettes: the test sees lost rays
    std::string key;
    const ShapedTable u = shapedTableFromBytes(shapedTableToBytes(t, "the key"), "x.shaped", key);
    EXPECT_EQ(key, "the key");
    EXPECT_EQ(u.lensHash, t.lensHash);
    EXPECT_EQ(u.maxAngleDeg, t.maxAngleDeg);
    EXPECT_EQ(u.wavelengthsNm, t.wavelengthsNm);
    EXPECT_EQ(u.iris.blades, t.iris.blades);
    EXPECT_EQ(u.iris.radius, t.iris.radius);
    EXPECT_EQ(u.ghostCount, t.ghostCount);
    ASSERT_EQ(u.ghosts.size(), t.ghosts.size());
    double worst = 0.0; // in steps
    for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
        const ShapedGhost &a = t.ghosts[g], &b = u.ghosts[g];
        EXPECT_EQ(b.pair, a.pair);
        EXPECT_EQ(b.grid, a.grid);
        EXPECT_EQ(b.apertureSteps, a.apertureSteps);
        EXPECT_EQ(b.stopCrossings, a.stopCrossings);
        const std::size_t S = a.stride();
        for (std::size_t w = 0; w < a.meshes.size(); ++w)
            for (std::size_t z = 0; z < S; ++z) {
                // The step: the attribute's range over the angles at this wavelength, rays not lost.
                float lo = std::numeric_limits<float>::infinity(), hi = -lo;
                for (const ShapedMesh& m : a.meshes[w])
                    for (std::size_t v = 0; v < m.data.size(); v += S)
                        if (!std::isnan(m.data[v]) && std::isfinite(m.data[v + z]))
                            lo = std::min(lo, m.data[v + z]), hi = std::max(hi, m.data[v + z]);
                const double step = hi > lo ? (double(hi) - lo) / 65534.0 : 0.0;
                const double slack = 1e-6 * std::max(std::abs(lo), std::abs(hi));
                for (std::size_t k = 0; k < a.meshes[w].size(); ++k) {
                    const ShapedMesh &m = a.meshes[w][k], &n = b.meshes[w][k];
                    EXPECT_EQ(n.flux, m.flux);
                    ASSERT_EQ(n.data.size(), m.data.size());
                    for (std::size_t v = 0; v < m.data.size(); v += S) {
                        // A lost ray (its landing x NaN) has no attribute; the others keep theirs.
                        const bool lost = std::isnan(m.data[v]) || std::isnan(m.data[v + z]);
                        ASSERT_EQ(std::isnan(n.data[v + z]), lost);
                        if (lost) continue;
                        const double err = std::abs(double(n.data[v + z]) - m.data[v + z]);
                        ASSERT_LE(err, 0.5 * step + slack);
                        if (step > 0.0) worst = std::max(worst, err / step);
                    }
                }
            }
    }
    EXPECT_GT(worst, 0.1); // the values were quantised, not stored as they are
}

// Anything but a complete, intact entry is refused with an input error: another file, another
// version, a truncated entry, a flipped bit in the header or in a ghost's data, trailing bytes.
TEST(ShapedCache, DamagedEntriesAreRefused) {
    const std::string bytes = shapedTableToBytes(buildShapedTable(cooke(), small()), "k");
    std::string key;
    EXPECT_NO_THROW(shapedTableFromBytes(bytes, "x.shaped", key));
    auto refused = [&](std::string b, const std::string& what) {
        try {
            shapedTableFromBytes(b, "x.shaped", key);
            ADD_FAILURE() << what << ": accepted";
        } catch (const Error& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Input) << what;
            EXPECT_NE(std::string(e.what()).find("x.shaped"), std::string::npos) << what << ": " << e.what();
        }
    };
    refused("", "empty");
    refused("{\"ghosts\": []}", "JSON");
    std::string v = bytes;
    v[8] = 7;
    refused(v, "version 7");
    for (std::size_t cut : {std::size_t(10), bytes.size() / 2, bytes.size() - 1})
        refused(bytes.substr(0, cut), "truncated at " + std::to_string(cut));
    for (std::size_t at : {std::size_t(30), bytes.size() / 2, bytes.size() - 5}) {
        std::string f = bytes;
        f[at] = static_cast<char>(f[at] ^ 0x10);
        refused(f, "bit flipped at " + std::to_string(at));
    }
    refused(bytes + "x", "trailing byte");
}

// A miss builds and stores, a hit reads it back; another setting is another entry; a damaged entry is
// rebuilt with a note and replaced. The table a run draws is the stored one, hit or miss.
TEST(ShapedCache, HitsMissesAndRebuildsDamagedEntries) {
    test::TempDir dir;
    setenv("FF_CACHE_DIR", dir.path().c_str(), 1);
    CollectingReporter rep;
    bool cached = true;
    const ShapedTable first = shapedTableFor(cooke(), small(), true, rep, &cached);
    EXPECT_FALSE(cached);
    std::size_t entries = 0;
    std::filesystem::path file;
    for (const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries, file = e.path();
    ASSERT_EQ(entries, 1u);
    const ShapedTable second = shapedTableFor(cooke(), small(), true, rep, &cached);
    EXPECT_TRUE(cached);
    ASSERT_EQ(second.ghosts.size(), first.ghosts.size());
    for (std::size_t g = 0; g < first.ghosts.size(); ++g)
        for (std::size_t w = 0; w < first.ghosts[g].meshes.size(); ++w)
            for (std::size_t a = 0; a < first.ghosts[g].meshes[w].size(); ++a) {
                const auto &x = first.ghosts[g].meshes[w][a].data, &y = second.ghosts[g].meshes[w][a].data;
                ASSERT_EQ(x.size(), y.size());
                for (std::size_t i = 0; i < x.size(); ++i)
                    ASSERT_TRUE(x[i] == y[i] || (std::isnan(x[i]) && std::isnan(y[i])));
            }
    EXPECT_TRUE(rep.diagnostics.empty());

    TableSettings other = small();
    other.angles = 6;
    EXPECT_NE(shapedCacheKey(cooke(), other), shapedCacheKey(cooke(), small()));
    shapedTableFor(cooke(), other, true, rep, &cached);
    EXPECT_FALSE(cached);
    entries = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
    EXPECT_EQ(entries, 2u);

    std::string damaged = test::readFile(file);
    damaged.resize(damaged.size() / 3);
    test::writeFile(file, damaged);
    shapedTableFor(cooke(), small(), true, rep, &cached);
    EXPECT_FALSE(cached);
    ASSERT_EQ(rep.diagnostics.size(), 1u);
    EXPECT_NE(rep.diagnostics[0].message.find("rebuilding"), std::string::npos);
    std::string key;
    EXPECT_NO_THROW(shapedTableFromBytes(test::readFile(file), file.string(), key));
    EXPECT_EQ(key, shapedCacheKey(cooke(), small()));
    unsetenv("FF_CACHE_DIR");
}
