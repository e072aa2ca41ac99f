#include "diffraction/psf_cache.h"

#include "core/byte_io.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/text.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <zlib.h>

namespace fs = std::filesystem;

namespace ff::diffraction {

namespace {

constexpr char kMagic[8] = {'F', 'F', 'P', 'S', 'F', '\0', '\0', '\0'};
constexpr std::uint32_t kVersion = 5;
constexpr std::uintmax_t kMaxEntryBytes = std::uintmax_t(1) << 31; // within zlib's 32-bit CRC length

std::uint32_t crc(std::string_view s) {
    return static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(s.data()), static_cast<uInt>(s.size())));
}

} // namespace

std::string psfCacheKey(const Aperture& a, const PsfSettings& s) {
    std::string key = "psf " + std::to_string(kVersion) + "; blades " + std::to_string(a.blades) + "; rotation " +
                      text::roundTrip(a.rotationRad) + "; N " + text::roundTrip(a.fNumber) + "; pitch " +
                      text::roundTrip(s.pitchMm) + "; transform " + std::to_string(s.transform) + "; nm";
    for (double l : s.wavelengthsNm) key += " " + text::roundTrip(l);
    if (s.wavelengthsNm.empty()) key += " default";
    if (s.mask && !s.mask->empty()) key += "; " + s.mask->key;
    return key;
}

std::string psfToBytes(const Psf& psf, const std::string& key) {
    std::string out(kMagic, sizeof kMagic);
    putBytes(out, kVersion);
    putBytes(out, static_cast<std::uint64_t>(key.size()));
    out += key;
    putBytes(out, static_cast<std::int32_t>(psf.radius));
    putBytes(out, psf.outside);
    putBytes(out, psf.edge);
    putBytes(out, static_cast<std::uint32_t>(psf.wavelengthsNm.size()));
    for (std::size_t i = 0; i < psf.wavelengthsNm.size(); ++i) {
        putBytes(out, psf.wavelengthsNm[i]);
        putBytes(out, static_cast<std::int32_t>(i < psf.binning.size() ? psf.binning[i] : 0));
    }
    for (const auto& c : psf.channel) out.append(reinterpret_cast<const char*>(c.data()), c.size() * sizeof(float));
    for (double a : psf.far.airy) putBytes(out, a);
    putBytes(out, static_cast<std::uint32_t>(psf.far.lines.size()));
    for (const FarField::Line& l : psf.far.lines) {
        putBytes(out, l.nx);
        putBytes(out, l.ny);
        putBytes(out, l.step);
        putBytes(out, static_cast<std::int32_t>(l.half));
        for (int c = 0; c < 3; ++c) {
            const std::vector<double>& v = l.profile[static_cast<std::size_t>(c)];
            out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
        }
    }
    putBytes(out, crc(out));
    return out;
}

Psf psfFromBytes(std::string_view bytes, const std::string& file, std::string& key) {
    auto bad = [&](const std::string& why) { throw Error(ErrorKind::Input, SourceLocation{file}, why); };
    if (bytes.size() < sizeof kMagic + 4 || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        bad("not a FourierFlare PSF");
    std::uint32_t stored = 0;
    std::memcpy(&stored, bytes.data() + bytes.size() - 4, 4);
    if (crc(bytes.substr(0, bytes.size() - 4)) != stored) bad("the PSF fails its CRC");
    ByteReader r{bytes.substr(0, bytes.size() - 4), sizeof kMagic, file, "the PSF is truncated"};
    if (r.get<std::uint32_t>() != kVersion) bad("the PSF is of another format version");
    const auto keyBytes = r.get<std::uint64_t>();
    key = std::string(r.take(static_cast<std::size_t>(std::min<std::uint64_t>(keyBytes, bytes.size()))));
    Psf p;
    p.radius = r.get<std::int32_t>();
    p.outside = r.get<double>();
    p.edge = r.get<double>();
    const auto wavelengths = r.get<std::uint32_t>();
    if (p.radius < 0 || p.radius > 1 << 14 || wavelengths > 1024) bad("the PSF's sizes are out of range");
    for (std::uint32_t i = 0; i < wavelengths; ++i) {
        p.wavelengthsNm.push_back(r.get<double>());
        p.binning.push_back(r.get<std::int32_t>());
    }
    const std::size_t n = static_cast<std::size_t>(p.width()) * p.width();
    for (auto& c : p.channel) {
        const std::string_view v = r.take(n * sizeof(float));
        c.resize(n);
        std::memcpy(c.data(), v.data(), v.size());
    }
    for (double& a : p.far.airy) a = r.get<double>();
    const auto lines = r.get<std::uint32_t>();
    if (lines > 1024) bad("the PSF's far field is out of range");
    for (std::uint32_t i = 0; i < lines; ++i) {
        FarField::Line l;
        l.nx = r.get<double>();
        l.ny = r.get<double>();
        l.step = r.get<double>();
        l.half = r.get<std::int32_t>();
        if (!(l.step > 0.0) || l.half < 1 || l.half > 1 << 16) bad("the PSF's far field is out of range");
        for (int c = 0; c < 3; ++c) {
            std::vector<double>& v = l.profile[static_cast<std::size_t>(c)];
            v.resize(static_cast<std::size_t>(2 * l.half + 1));
            const std::string_view b = r.take(v.size() * sizeof(double));
            std::memcpy(v.data(), b.data(), b.size());
        }
        p.far.lines.push_back(std::move(l));
    }
    if (r.at != r.bytes.size()) bad("the PSF has trailing bytes");
    return p;
}

Psf cachedPixelPsf(const Aperture& aperture, const PsfSettings& settings, bool useCache, Reporter& reporter,
                   bool* fromCache) {
    if (fromCache) *fromCache = false;
    if (settings.pupil || !useCache) return pixelPsf(aperture, settings);
    const std::string key = psfCacheKey(aperture, settings);
    const fs::path file = cacheDirectory() / (hashHex(key) + ".psf");
    std::error_code ec;
    if (fs::exists(file, ec)) {
        try {
            std::string stored;
            Psf p = psfFromBytes(readFileBytes(file, kMaxEntryBytes), file.string(), stored);
            if (stored == key) {
                if (fromCache) *fromCache = true;
                return p;
            }
            reporter.note({file.string()}, "cached PSF does not match the iris or the pixel pitch; recomputing it");
        } catch (const Error& e) {
            reporter.note({file.string()}, "cached PSF is unreadable (" + e.message() + "); recomputing it");
        }
    }
    Psf p = pixelPsf(aperture, settings);
    storeCacheEntry(file, psfToBytes(p, key), "PSF", reporter);
    return p;
}

} // namespace ff::diffraction
