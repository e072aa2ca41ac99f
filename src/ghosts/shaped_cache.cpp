#include "ghosts/shaped_cache.h"

#include "core/byte_io.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_integer.h"
#include "core/text.h"
#include "ghosts/table_json.h"
#include "optics/lens_loader.h"

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <zlib.h>
#include <zstd.h>

namespace fs = std::filesystem;

namespace ff::ghosts {

namespace {

constexpr char kMagic[8] = {'F', 'F', 'S', 'H', 'A', 'P', 'E', 'D'};
constexpr std::uint32_t kVersion = 4;
constexpr std::uint16_t kLost = 65535;
constexpr double kLevels = 65534.0;
constexpr std::uintmax_t kMaxEntryBytes = std::uintmax_t(4) << 30;
constexpr std::uint64_t kMaxHeaderBytes = std::uint64_t(1) << 30;

std::size_t vertices(const ShapedGhost& g) {
    return static_cast<std::size_t>(g.grid + 1) * (g.grid + 1);
}

// A vertex whose ray was lost (its landing x is NaN): none of its attributes is used.
bool lostAt(const ShapedMesh& m, std::size_t S, std::size_t v) {
    return std::isnan(m.data[v * S]);
}

// The range [lo, hi] of attribute z over the finite values of a ghost's meshes at one wavelength,
// at vertices not lost (0, 0 where there are none).
std::pair<float, float> range(const std::vector<ShapedMesh>& perAngle, std::size_t V, std::size_t S, std::size_t z) {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (const ShapedMesh& m : perAngle)
        for (std::size_t v = 0; v < V && !m.data.empty(); ++v) {
            const float x = m.data[v * S + z];
            if (std::isfinite(x) && !lostAt(m, S, v)) lo = std::min(lo, x), hi = std::max(hi, x);
        }
    if (!(hi >= lo)) lo = hi = 0.0f;
    return {lo, hi};
}

// An attribute's values as 16-bit codes over its range [lo, hi]: lo + c s, s = (hi - lo) / 65534;
// kLost for a non-finite value or a lost ray. Encoding and decoding compute the same values: a run
// draws the same meshes cold and warm, bit for bit.
struct Coding {
    float lo = 0.0f;
    double scale = 0.0, step = 0.0; // 1 / s, s

    Coding(float l, float h)
        : lo(l), scale(h > l ? kLevels / (double(h) - double(l)) : 0.0), step((double(h) - double(l)) / kLevels) {}

    std::uint16_t code(float x) const {
        return std::isfinite(x)
                   ? static_cast<std::uint16_t>(std::clamp(std::lround((double(x) - lo) * scale), 0L, 65534L))
                   : kLost;
    }
    float value(std::uint16_t c) const {
        return c == kLost ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(lo + double(c) * step);
    }
};

// The prediction of a mesh's code at grid vertex v = (i, j) from the previous angle's codes `prev`
// and this angle's codes before v in row-major order (modulo 2^16): prev(v) plus the plane through
// the change since the previous angle at the three neighbours behind v, exact for a change that is
// bilinear over the grid (the previous vertex on the first row and column). The first angle's
// `prev` is zero. Smooth attributes leave residuals of a few steps, which compress well.
std::uint16_t predict(const std::vector<std::uint16_t>& c, const std::vector<std::uint16_t>& prev, std::size_t v,
                      std::size_t row) {
    const std::size_t i = v % row, j = v / row;
    auto d = [&](std::size_t u) { return static_cast<std::uint16_t>(c[u] - prev[u]); };
    std::uint16_t change = 0;
    if (i > 0 && j > 0)
        change = static_cast<std::uint16_t>(d(v - 1) + d(v - row) - d(v - row - 1));
    else if (i > 0 || j > 0)
        change = d(i > 0 ? v - 1 : v - row);
    return static_cast<std::uint16_t>(prev[v] + change);
}

// Walks one attribute of a ghost's meshes at one wavelength in the format's order, angle by angle,
// calling step(angle, v, prediction) -> code for every vertex of every present mesh.
template <typename Step>
void walkCodes(const std::vector<ShapedMesh>& perAngle, std::size_t V, std::size_t row, Step&& step) {
    std::vector<std::uint16_t> prev(V, 0), code(V, 0);
    for (std::size_t a = 0; a < perAngle.size(); ++a) {
        if (perAngle[a].data.empty()) continue;
        for (std::size_t v = 0; v < V; ++v) code[v] = step(a, v, predict(code, prev, v, row));
        std::swap(prev, code);
    }
}

// One ghost's meshes in the format above, before compression: per wavelength, every present mesh's
// lost vertices (one byte each), then per attribute its range over the angles and, angle by angle,
// the residuals from the prediction, low bytes then high bytes. A lost vertex's code is its
// prediction (residual 0): the decoder gives it NaN.
std::string encodeGhost(const ShapedGhost& g) {
    std::string out;
    const std::size_t V = vertices(g), S = g.stride(), row = static_cast<std::size_t>(g.grid) + 1;
    for (const auto& perAngle : g.meshes) {
        for (const ShapedMesh& m : perAngle)
            for (std::size_t v = 0; v < V && !m.data.empty(); ++v) out.push_back(lostAt(m, S, v) ? 1 : 0);
        for (std::size_t z = 0; z < S; ++z) {
            // Named values, not a structured binding: the lambda below uses lo (clang 14 cannot
            // capture a binding).
            const std::pair<float, float> bounds = range(perAngle, V, S, z);
            const float lo = bounds.first, hi = bounds.second;
            putBytes(out, lo);
            putBytes(out, hi);
            const Coding coding(lo, hi);
            std::string low, high;
            walkCodes(perAngle, V, row, [&](std::size_t a, std::size_t v, std::uint16_t pred) {
                const ShapedMesh& m = perAngle[a];
                const std::uint16_t c = lostAt(m, S, v) ? pred : coding.code(m.data[v * S + z]);
                const auto r = static_cast<std::uint16_t>(c - pred);
                low.push_back(static_cast<char>(r & 0xff));
                high.push_back(static_cast<char>(r >> 8));
                return c;
            });
            out += low;
            out += high;
        }
    }
    return out;
}

// One ghost's meshes as decodeGhost gives them back from encodeGhost's bytes, computed in place.
void quantiseGhost(ShapedGhost& g) {
    const std::size_t V = vertices(g), S = g.stride();
    for (auto& perAngle : g.meshes) {
        std::vector<std::vector<char>> lost(perAngle.size(), std::vector<char>(V, 0));
        for (std::size_t a = 0; a < perAngle.size(); ++a)
            for (std::size_t v = 0; v < V && !perAngle[a].data.empty(); ++v) lost[a][v] = lostAt(perAngle[a], S, v);
        for (std::size_t z = 0; z < S; ++z) {
            const auto [lo, hi] = range(perAngle, V, S, z);
            const Coding coding(lo, hi);
            for (std::size_t a = 0; a < perAngle.size(); ++a)
                for (std::size_t v = 0; v < V && !perAngle[a].data.empty(); ++v) {
                    float& x = perAngle[a].data[v * S + z];
                    x = coding.value(lost[a][v] ? kLost : coding.code(x));
                }
        }
    }
}

// Undoes predict() for one mesh. With d = c - prev (the change since the previous angle) the
// prediction is d(i, j) = d(i-1, j) + d(i, j-1) - d(i-1, j-1) + residual, so d is the 2-D running sum
// of the residuals: along each row, plus the row above (modulo 2^16, as predict()). `low`, `high`:
// the mesh's residual bytes.
void unpredictMesh(const unsigned char* low, const unsigned char* high, const std::uint16_t* prev, std::uint16_t* c,
                   std::uint16_t* d, std::size_t row, std::size_t V) {
    for (std::size_t v0 = 0; v0 < V; v0 += row) {
        std::uint16_t sum = 0; // this row's residuals so far
        for (std::size_t v = v0; v < v0 + row; ++v) {
            sum = static_cast<std::uint16_t>(sum + (low[v] | high[v] << 8));
            d[v] = static_cast<std::uint16_t>(sum + (v0 > 0 ? d[v - row] : 0));
            c[v] = static_cast<std::uint16_t>(prev[v] + d[v]);
        }
    }
}

// encodeGhost's bytes back into the ghost's meshes (whose present ones are sized). Decoded angle by
// angle, every attribute of a mesh at once, so that each vertex's floats are written together.
void decodeGhost(ShapedGhost& g, std::string_view raw, const std::string& file) {
    const std::size_t V = vertices(g), S = g.stride(), row = static_cast<std::size_t>(g.grid) + 1;
    ByteReader r{raw, 0, file, "truncated shaped-table entry"};
    std::vector<std::uint16_t> prev(S * V), code(S * V), change(V);
    std::vector<Coding> coding;
    std::vector<const unsigned char*> low(S), high(S);
    for (auto& perAngle : g.meshes) {
        std::vector<const unsigned char*> lost(perAngle.size(), nullptr);
        std::size_t present = 0;
        for (std::size_t a = 0; a < perAngle.size(); ++a)
            if (!perAngle[a].data.empty())
                lost[a] = reinterpret_cast<const unsigned char*>(r.take(V).data()), ++present;
        coding.clear();
        for (std::size_t z = 0; z < S; ++z) {
            const float l = r.get<float>(), h = r.get<float>();
            if (!std::isfinite(l) || !std::isfinite(h) || h < l)
                throw Error(ErrorKind::Input, SourceLocation{file}, "bad quantisation range");
            coding.emplace_back(l, h);
            low[z] = reinterpret_cast<const unsigned char*>(r.take(present * V).data());
            high[z] = reinterpret_cast<const unsigned char*>(r.take(present * V).data());
        }
        std::fill(prev.begin(), prev.end(), std::uint16_t(0));
        for (std::size_t a = 0, p = 0; a < perAngle.size(); ++a) {
            if (perAngle[a].data.empty()) continue;
            for (std::size_t z = 0; z < S; ++z)
                unpredictMesh(low[z] + p * V, high[z] + p * V, prev.data() + z * V, code.data() + z * V, change.data(),
                              row, V);
            float* out = perAngle[a].data.data();
            for (std::size_t v = 0; v < V; ++v, out += S)
                for (std::size_t z = 0; z < S; ++z) {
                    out[z] = coding[z].value(lost[a][v] != 0 ? kLost : code[z * V + v]);
                }
            std::swap(prev, code);
            ++p;
        }
    }
    if (r.at != raw.size())
        throw Error(ErrorKind::Input, SourceLocation{file}, "shaped-table entry has trailing bytes");
}

// Zstandard at level 3, each frame with its content's checksum (XXH64, checked as it decompresses):
// against zlib's level 1 and a CRC-32 of each chunk on the double Gauss's meshes, 12 % smaller and
// decompressed 4 times faster (docs/performance.md, "The table").
std::string compress(const std::string& raw) {
    std::string out(ZSTD_compressBound(raw.size()), '\0');
    ZSTD_CCtx* cctx = ZSTD_createCCtx();
    if (!cctx) throw Error(ErrorKind::Runtime, "zstd could not start compressing a shaped table");
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, 3);
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
    const std::size_t n = ZSTD_compress2(cctx, out.data(), out.size(), raw.data(), raw.size());
    ZSTD_freeCCtx(cctx);
    if (ZSTD_isError(n))
        throw Error(ErrorKind::Runtime, std::string("zstd could not compress a shaped table: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
}

// The chunk decompressed into exactly the n bytes at `raw`, its checksum checked; or false.
bool decompress(std::string_view chunk, char* raw, std::size_t n) {
    // A frame without its checksum is not one compress() wrote: a damaged chunk must not pass unchecked.
    // RFC 8878: the magic number 0xFD2FB528 (little-endian), then the frame header's descriptor, whose
    // bit 2 is the content-checksum flag.
    if (chunk.size() < 5 || chunk.substr(0, 4) != std::string_view("\x28\xB5\x2F\xFD", 4) || !(chunk[4] & 0x04))
        return false;
    const std::size_t got = ZSTD_decompress(raw, n, chunk.data(), chunk.size());
    return !ZSTD_isError(got) && got == n && ZSTD_findFrameCompressedSize(chunk.data(), chunk.size()) == chunk.size();
}

std::uint32_t crc(std::string_view s) {
    return static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(s.data()), static_cast<uInt>(s.size())));
}

} // namespace

std::string shapedTableToBytes(const ShapedTable& t, const std::string& key) {
    std::vector<std::string> chunks(t.ghosts.size());
    std::vector<std::uint64_t> rawSize(t.ghosts.size());
    tbb::parallel_for(std::size_t(0), t.ghosts.size(), [&](std::size_t g) {
        const std::string raw = encodeGhost(t.ghosts[g]);
        rawSize[g] = raw.size();
        chunks[g] = compress(raw);
    });
    nlohmann::json h;
    h["key"] = key;
    h["lens_name"] = t.lensName;
    h["lens_hash"] = t.lensHash;
    h["max_angle_deg"] = t.maxAngleDeg;
    h["wavelengths_nm"] = t.wavelengthsNm;
    h["iris"] = {{"blades", t.iris.blades}, {"rotation_rad", t.iris.rotationRad}, {"radius", t.iris.radius}};
    h["sensor_z_mm"] = t.sensorZ;
    h["sensor_size_mm"] = {t.sensorSizeMm.first, t.sensorSizeMm.second};
    h["pupil_radius_mm"] = t.pupilRadiusMm;
    h["direct_y_mm"] = t.directY;
    // A two-dimensional table has no fits (fitShapedTable), its field grid instead.
    if (t.twoDimensional()) {
        h["field_grid"] = {{"x", t.fieldGrid.x},
                           {"y", t.fieldGrid.y},
                           {"max_tan_x", t.fieldGrid.maxTanX},
                           {"max_tan_y", t.fieldGrid.maxTanY}};
        h["direct_flux"] = t.directFlux;
    } else
        h["fitted"] = tableToJson(t.fitted, true);
    h["ghost_count"] = t.ghostCount;
    h["rays"] = t.rays;
    h["angles"] = t.angles();
    h["ghosts"] = nlohmann::json::array();
    for (std::size_t g = 0; g < t.ghosts.size(); ++g) {
        const ShapedGhost& gh = t.ghosts[g];
        nlohmann::json j = {{"first", gh.pair.first},
                            {"second", gh.pair.second},
                            {"grid", gh.grid},
                            {"pupil_rect_mm", {gh.pupilX0, gh.pupilY0, gh.pupilX1, gh.pupilY1}},
                            {"aperture_steps", gh.apertureSteps},
                            {"stop_crossings", gh.stopCrossings},
                            {"raw_bytes", rawSize[g]},
                            {"bytes", chunks[g].size()}};
        for (const auto& perAngle : gh.meshes) {
            nlohmann::json flux = nlohmann::json::array(), present = nlohmann::json::array();
            for (const ShapedMesh& m : perAngle) flux.push_back(m.flux), present.push_back(!m.data.empty());
            j["flux"].push_back(flux);
            j["present"].push_back(present);
        }
        h["ghosts"].push_back(j);
    }
    const std::string header = h.dump();
    std::string out(kMagic, sizeof kMagic);
    putBytes(out, kVersion);
    putBytes(out, static_cast<std::uint64_t>(header.size()));
    out += header;
    putBytes(out, crc(header));
    for (const std::string& c : chunks) out += c;
    return out;
}

namespace {

// The entry's header (magic, format version, JSON with its CRC), checked; r is left after it.
std::string_view readHeader(ByteReader& r, const std::string& file) {
    if (r.take(sizeof kMagic) != std::string_view(kMagic, sizeof kMagic))
        throw Error(ErrorKind::Input, SourceLocation{file}, "not a shaped-table entry");
    if (const auto v = r.get<std::uint32_t>(); v != kVersion)
        throw Error(ErrorKind::Input, SourceLocation{file},
                    "shaped-table format version " + std::to_string(v) + ", expected " + std::to_string(kVersion));
    const std::uint64_t n = r.get<std::uint64_t>();
    if (n > kMaxHeaderBytes) throw Error(ErrorKind::Input, SourceLocation{file}, "shaped-table header too large");
    const std::string_view header = r.take(n);
    if (r.get<std::uint32_t>() != crc(header))
        throw Error(ErrorKind::Input, SourceLocation{file}, "shaped-table header fails its CRC");
    return header;
}

// The fitted table stored in a header.
GhostTable fittedFrom(const nlohmann::json& h, const std::string& file) {
    GhostTable t = tableFromJson(h.at("fitted").get<std::string>(), file);
    t.settingsKey = h.at("key").get<std::string>();
    return t;
}

// A two-dimensional table's field grid from its header.
ShapedTable::FieldGrid fieldGridFrom(const nlohmann::json& j, const std::string& file) {
    ShapedTable::FieldGrid g;
    g.x = jsonInteger<int>(j.at("x"));
    g.y = jsonInteger<int>(j.at("y"));
    g.maxTanX = j.at("max_tan_x").get<double>();
    g.maxTanY = j.at("max_tan_y").get<double>();
    if (g.x < 2 || g.y < 2 || g.x > 1024 || g.y > 1024 || !(g.maxTanX > 0.0 && g.maxTanX < 1e3) ||
        !(g.maxTanY > 0.0 && g.maxTanY < 1e3))
        throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table field grid");
    return g;
}

// The table's per-field arrays against its field count A and wavelength count.
void checkDimensions(const ShapedTable& t, int A, const std::string& file) {
    const std::size_t W = t.wavelengthsNm.size();
    if (A < 1 || A > 10000 || W < 1 || W > 64 || t.directY.size() != W || t.fitted.wavelengthsNm.size() != W ||
        (t.twoDimensional() ? A != t.fieldGrid.x * t.fieldGrid.y
                            : t.fitted.anglesDeg.size() != static_cast<std::size_t>(A)))
        throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table dimensions");
    for (const auto& row : t.directY)
        if (row.size() != static_cast<std::size_t>(A))
            throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table dimensions");
    if (t.twoDimensional() && t.directFlux.size() != W)
        throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table dimensions");
    for (const auto& row : t.directFlux)
        for (const double f : row)
            if (row.size() != static_cast<std::size_t>(A) || !(f >= 0.0 && f < 1e12))
                throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table direct flux");
}

} // namespace

ShapedTable shapedTableFromBytes(std::string_view bytes, const std::string& file, std::string& key) {
    ByteReader r{bytes, 0, file, "truncated shaped-table entry"};
    const std::string_view header = readHeader(r, file);
    ShapedTable t;
    std::vector<std::string_view> chunks;
    std::vector<std::uint64_t> rawSize;
    std::vector<std::vector<char>> presentMeshes; // per ghost, [wavelength][angle]
    try {
        const nlohmann::json h = nlohmann::json::parse(header);
        key = h.at("key").get<std::string>();
        t.lensName = h.at("lens_name").get<std::string>();
        t.lensHash = h.at("lens_hash").get<std::string>();
        t.maxAngleDeg = h.at("max_angle_deg").get<double>();
        t.wavelengthsNm = h.at("wavelengths_nm").get<std::vector<double>>();
        const auto& iris = h.at("iris");
        const int blades = jsonInteger<int>(iris.at("blades"));
        const double radius = iris.at("radius").get<double>();
        if ((blades != 0 && (blades < 3 || blades > 64)) || !(radius > 0.0 && radius < 1e6) ||
            !(t.maxAngleDeg >= 0.0 && t.maxAngleDeg < 90.0))
            throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table iris or field");
        t.iris = trace::Iris(blades, iris.at("rotation_rad").get<double>(), iris.at("radius").get<double>());
        t.sensorZ = h.at("sensor_z_mm").get<double>();
        const auto size = h.at("sensor_size_mm").get<std::vector<double>>();
        if (size.size() != 2) throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-table sensor");
        t.sensorSizeMm = {size[0], size[1]};
        t.pupilRadiusMm = h.at("pupil_radius_mm").get<double>();
        t.directY = h.at("direct_y_mm").get<std::vector<std::vector<double>>>();
        if (const auto grid = h.find("field_grid"); grid != h.end()) {
            t.fieldGrid = fieldGridFrom(*grid, file);
            t.directFlux = h.at("direct_flux").get<std::vector<std::vector<double>>>();
            t.fitted.lensName = t.lensName;
            t.fitted.lensHash = t.lensHash;
            t.fitted.settingsKey = key;
            t.fitted.sensorZ = t.sensorZ;
            t.fitted.sensorSizeMm = t.sensorSizeMm;
            t.fitted.wavelengthsNm = t.wavelengthsNm;
        } else {
            t.fitted = fittedFrom(h, file);
        }
        t.ghostCount = jsonInteger<std::size_t>(h.at("ghost_count"));
        t.rays = jsonInteger<std::size_t>(h.at("rays"));
        t.buildSeconds = h.value("build_seconds", 0.0);
        const int A = jsonInteger<int>(h.at("angles"));
        const std::size_t W = t.wavelengthsNm.size();
        checkDimensions(t, A, file);
        for (const auto& j : h.at("ghosts")) {
            ShapedGhost g;
            g.pair = {jsonInteger<std::size_t>(j.at("first")), jsonInteger<std::size_t>(j.at("second"))};
            g.grid = jsonInteger<int>(j.at("grid"));
            g.apertureSteps = jsonIntegers<std::size_t>(j.at("aperture_steps"));
            g.stopCrossings = jsonInteger<std::size_t>(j.at("stop_crossings"));
            const auto rect = j.at("pupil_rect_mm").get<std::vector<double>>();
            if (rect.size() != 4) throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-ghost layout");
            g.pupilX0 = rect[0], g.pupilY0 = rect[1], g.pupilX1 = rect[2], g.pupilY1 = rect[3];
            if (g.grid < 1 || g.grid > 4096 || g.apertureSteps.size() > 1024 || g.stopCrossings > 16)
                throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-ghost layout");
            const auto& flux = j.at("flux");
            const auto& present = j.at("present");
            if (flux.size() != W || present.size() != W)
                throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-ghost layout");
            std::uint64_t expected = 0;
            g.meshes.assign(W, std::vector<ShapedMesh>(static_cast<std::size_t>(A)));
            for (std::size_t w = 0; w < W; ++w) {
                if (flux[w].size() != static_cast<std::size_t>(A) || present[w].size() != static_cast<std::size_t>(A))
                    throw Error(ErrorKind::Input, SourceLocation{file}, "bad shaped-ghost layout");
                std::uint64_t meshes = 0;
                for (std::size_t a = 0; a < static_cast<std::size_t>(A); ++a) {
                    g.meshes[w][a].flux = flux[w][a].get<double>();
                    meshes += present[w][a].get<bool>() ? 1 : 0;
                }
                // The lost-vertex bytes, then per attribute its range and two bytes per value.
                expected += meshes * vertices(g) + g.stride() * (8 + 2 * meshes * vertices(g));
            }
            rawSize.push_back(jsonInteger<std::uint64_t>(j.at("raw_bytes")));
            chunks.push_back(r.take(jsonInteger<std::uint64_t>(j.at("bytes"))));
            // A zstd frame expands at most 32768-fold (a 128 KiB run in a 4-byte RLE block): a layout
            // beyond that is not this data's, and nothing is allocated for it.
            if (rawSize.back() != expected || expected > 32768 * chunks.back().size())
                throw Error(ErrorKind::Input, SourceLocation{file}, "shaped-ghost size does not match its layout");
            // The present meshes are sized as each ghost decodes: the 100s of MB in parallel.
            std::vector<char>& p = presentMeshes.emplace_back(W * static_cast<std::size_t>(A), 0);
            for (std::size_t w = 0; w < W; ++w)
                for (std::size_t a = 0; a < static_cast<std::size_t>(A); ++a)
                    p[w * static_cast<std::size_t>(A) + a] = present[w][a].get<bool>() ? 1 : 0;
            t.ghosts.push_back(std::move(g));
        }
    } catch (const nlohmann::json::exception& e) {
        throw Error(ErrorKind::Input, SourceLocation{file}, std::string("bad shaped-table header: ") + e.what());
    }
    if (r.at != bytes.size())
        throw Error(ErrorKind::Input, SourceLocation{file}, "shaped-table entry has trailing bytes");
    if (!t.twoDimensional() && t.fitted.ghosts.size() != t.ghosts.size())
        throw Error(ErrorKind::Input, SourceLocation{file}, "the fitted ghosts do not match the shaped ones");
    std::vector<std::string> errors(t.ghosts.size());
    tbb::parallel_for(std::size_t(0), t.ghosts.size(), [&](std::size_t g) {
        try {
            ShapedGhost& gh = t.ghosts[g];
            for (std::size_t w = 0, k = 0; w < gh.meshes.size(); ++w)
                for (ShapedMesh& m : gh.meshes[w])
                    if (presentMeshes[g][k++]) m.data.resize(vertices(gh) * gh.stride());
            const auto n = static_cast<std::size_t>(rawSize[g]);
            const std::unique_ptr<char[]> raw(new char[n]); // not zeroed: decompress() fills it or fails
            if (!decompress(chunks[g], raw.get(), n))
                throw Error(ErrorKind::Input, SourceLocation{file},
                            "shaped ghost " + std::to_string(g) + " does not decompress or fails its checksum");
            decodeGhost(gh, std::string_view(raw.get(), n), file);
        } catch (const Error& e) {
            errors[g] = e.message();
        }
    });
    for (const std::string& e : errors)
        if (!e.empty()) throw Error(ErrorKind::Input, SourceLocation{file}, e);
    return t;
}

fs::path cacheFile(const optics::Lens& lens, const TableSettings& s) {
    return cacheDirectory() / (hashHex(shapedCacheKey(lens, s)) + ".shaped");
}

namespace {

// Builds the table, stores it when useCache, and returns it as stored: a run draws the same ghosts
// cold and warm.
ShapedTable buildAndStore(const optics::Lens& lens, const TableSettings& s, bool useCache, Reporter& reporter,
                          const Progress& progress) {
    const std::string key = shapedCacheKey(lens, s);
    const fs::path file = cacheFile(lens, s);
    ShapedTable t = buildShapedTable(lens, s, progress);
    // The entry's bytes are a function of its key alone (the build's wall time is not stored):
    // processes that build the same entry at once store the same bytes.
    const std::string bytes = shapedTableToBytes(t, key);
    tbb::parallel_for(std::size_t(0), t.ghosts.size(), [&](std::size_t g) { quantiseGhost(t.ghosts[g]); });
    t.fitted.lensFile = lens.file;
    if (useCache) storeCacheEntry(file, bytes, "shaped table", reporter);
    return t;
}

} // namespace

ShapedTable shapedTableFor(const optics::Lens& lens, const TableSettings& s, bool useCache, Reporter& reporter,
                           bool* fromCache, const Progress& progress) {
    if (fromCache) *fromCache = false;
    const std::string key = shapedCacheKey(lens, s);
    const fs::path file = cacheFile(lens, s);
    if (useCache && fs::exists(file)) {
        try {
            std::string stored;
            ShapedTable t = shapedTableFromBytes(readFileBytes(file, kMaxEntryBytes), file.string(), stored);
            if (stored == key) {
                t.fitted.lensFile = lens.file;
                if (fromCache) *fromCache = true;
                return t;
            }
            reporter.note({file.string()}, "cached shaped table does not match the lens or settings; rebuilding it");
        } catch (const Error& e) {
            reporter.note({file.string()},
                          std::string("cached shaped table is unreadable (") + e.message() + "); rebuilding it");
        }
    }
    return buildAndStore(lens, s, useCache, reporter, progress);
}

GhostTable tableFor(const optics::Lens& lens, const TableSettings& s, bool useCache, const Progress& progress,
                    Reporter& reporter, bool* fromCache) {
    if (fromCache) *fromCache = false;
    optics::requireTraceable(lens); // an anamorphic lens's table has no fits
    const std::string key = shapedCacheKey(lens, s);
    const fs::path file = cacheFile(lens, s);
    // The fits are in the entry's header: only it is read.
    if (useCache && fs::exists(file)) {
        try {
            std::ifstream in(file, std::ios::binary);
            std::string head(sizeof kMagic + 12, '\0');
            in.read(head.data(), static_cast<std::streamsize>(head.size()));
            if (in.gcount() == static_cast<std::streamsize>(head.size())) {
                std::uint64_t n = 0;
                std::memcpy(&n, head.data() + sizeof kMagic + 4, sizeof n);
                if (n <= kMaxHeaderBytes) {
                    head.resize(head.size() + static_cast<std::size_t>(n) + 4);
                    in.read(head.data() + sizeof kMagic + 12, static_cast<std::streamsize>(n + 4));
                }
            }
            ByteReader r{head, 0, file.string(), "truncated shaped-table entry"};
            const nlohmann::json h = nlohmann::json::parse(readHeader(r, file.string()));
            if (h.at("key").get<std::string>() == key) {
                GhostTable t = fittedFrom(h, file.string());
                t.lensFile = lens.file;
                if (fromCache) *fromCache = true;
                return t;
            }
            reporter.note({file.string()}, "cached shaped table does not match the lens or settings; rebuilding it");
        } catch (const nlohmann::json::exception& e) {
            reporter.note({file.string()},
                          std::string("cached shaped table is unreadable (") + e.what() + "); rebuilding it");
        } catch (const Error& e) {
            reporter.note({file.string()},
                          std::string("cached shaped table is unreadable (") + e.message() + "); rebuilding it");
        }
    }
    return buildAndStore(lens, s, useCache, reporter, progress).fitted;
}

} // namespace ff::ghosts
