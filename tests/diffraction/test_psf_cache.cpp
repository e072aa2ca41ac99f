// The PSF cache: an entry reads back bit for bit, any damage is refused, a hit returns what the miss
// computed, another pitch is another entry, and a damaged entry is recomputed with a note.

#include "core/error.h"
#include "diffraction/psf_cache.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "test_support.h"

namespace ff::diffraction {
namespace {

const Aperture kIris{6, 0.1, 8.0};

PsfSettings small(double pitchMm = 0.012) {
    PsfSettings s;
    s.pitchMm = pitchMm;
    s.wavelengthsNm = {450.0, 550.0, 650.0};
    s.transform = 256;
    return s;
}

void expectSame(const Psf& a, const Psf& b) {
    EXPECT_EQ(a.radius, b.radius);
    EXPECT_EQ(a.outside, b.outside);
    EXPECT_EQ(a.edge, b.edge);
    EXPECT_EQ(a.wavelengthsNm, b.wavelengthsNm);
    EXPECT_EQ(a.binning, b.binning);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(a.channel[c], b.channel[c]) << c;
    EXPECT_EQ(a.far.airy, b.far.airy);
    ASSERT_EQ(a.far.lines.size(), b.far.lines.size());
    for (std::size_t i = 0; i < a.far.lines.size(); ++i) {
        const FarField::Line &p = a.far.lines[i], &q = b.far.lines[i];
        EXPECT_EQ(p.nx, q.nx);
        EXPECT_EQ(p.ny, q.ny);
        EXPECT_EQ(p.step, q.step);
        EXPECT_EQ(p.half, q.half);
        EXPECT_EQ(p.profile, q.profile);
    }
}

TEST(PsfCache, BytesRoundTripAndDamageIsRefused) {
    const Psf psf = pixelPsf(kIris, small());
    ASSERT_GT(psf.radius, 2);
    const std::string key = psfCacheKey(kIris, small());
    const std::string bytes = psfToBytes(psf, key);
    std::string back;
    expectSame(psfFromBytes(bytes, "entry", back), psf);
    EXPECT_EQ(back, key);
    for (std::size_t at : {std::size_t(0), std::size_t(9), std::size_t(20), bytes.size() / 2, bytes.size() - 1}) {
        std::string damaged = bytes;
        damaged[at] = static_cast<char>(damaged[at] ^ 0x04);
        EXPECT_THROW(psfFromBytes(damaged, "entry", back), Error) << "bit flipped at " << at;
    }
    EXPECT_THROW(psfFromBytes(bytes.substr(0, bytes.size() / 2), "entry", back), Error);
    EXPECT_THROW(psfFromBytes(bytes + "x", "entry", back), Error);
    EXPECT_THROW(psfFromBytes("", "entry", back), Error);
}

TEST(PsfCache, HitsMissesAndRecomputesDamagedEntries) {
    test::TempDir dir;
    setenv("FF_CACHE_DIR", dir.path().c_str(), 1);
    CollectingReporter rep;
    bool cached = true;
    const Psf first = cachedPixelPsf(kIris, small(), true, rep, &cached);
    EXPECT_FALSE(cached);
    expectSame(first, pixelPsf(kIris, small()));
    std::filesystem::path file;
    std::size_t entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries, file = e.path();
    ASSERT_EQ(entries, 1u);
    expectSame(cachedPixelPsf(kIris, small(), true, rep, &cached), first);
    EXPECT_TRUE(cached);
    EXPECT_TRUE(rep.diagnostics.empty());

    // Another pitch, another iris: other keys, other entries.
    EXPECT_NE(psfCacheKey(kIris, small(0.015)), psfCacheKey(kIris, small()));
    EXPECT_NE(psfCacheKey({5, 0.1, 8.0}, small()), psfCacheKey(kIris, small()));
    cachedPixelPsf(kIris, small(0.015), true, rep, &cached);
    EXPECT_FALSE(cached);
    entries = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
    EXPECT_EQ(entries, 2u);

    std::string damaged = test::readFile(file);
    damaged[damaged.size() / 2] ^= 0x01;
    test::writeFile(file, damaged);
    expectSame(cachedPixelPsf(kIris, small(), true, rep, &cached), first);
    EXPECT_FALSE(cached);
    ASSERT_EQ(rep.diagnostics.size(), 1u);
    EXPECT_NE(rep.diagnostics[0].message.find("recomputing"), std::string::npos);
    EXPECT_TRUE(cachedPixelPsf(kIris, small(), true, rep, &cached).radius == first.radius && cached);

    // Without the cache nothing is read or stored.
    std::filesystem::remove_all(dir.path() / "none");
    setenv("FF_CACHE_DIR", (dir.path() / "none").c_str(), 1);
    cachedPixelPsf(kIris, small(), false, rep, &cached);
    EXPECT_FALSE(cached);
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "none"));
    unsetenv("FF_CACHE_DIR");
}

} // namespace
} // namespace ff::diffraction
