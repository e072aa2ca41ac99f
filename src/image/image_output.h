#pragma once
// Writing images: float EXR with named channels and metadata, and tonemapped 8-bit PNG previews.
// Both go through a temporary file in the target folder and a rename, so a failed write never leaves
// a partial or corrupted output. Errors throw ff::Error (Runtime).

#include <string>
#include <utility>
#include <vector>

namespace ff::image {

/// String attributes recorded in the file header (tool version, command line, lens hash, ...).
using Metadata = std::vector<std::pair<std::string, std::string>>;

/// Threads OpenEXR compresses and decompresses with (process-wide; n >= 1). The bytes written do not
/// depend on it: each chunk of scanlines is compressed on its own, and the chunks are written in order.
void setExrThreads(int n);

/// Writes a single-part, zip-compressed float EXR; `pixels` is width x height x channels.size(),
/// interleaved, rows top to bottom. pixelAspectRatio != 1 is recorded in the header (EXR's
/// pixelAspectRatio: an anamorphic frame's squeeze, which viewers undo on display).
void writeExr(const std::string& path, int width, int height, const std::vector<std::string>& channels,
              const std::vector<float>& pixels, const Metadata& metadata, double pixelAspectRatio = 1.0);

/// An interleaved RGB image stretched horizontally by `factor` (> 0) to round(width x factor) columns,
/// each output pixel centre sampling the input linearly between its neighbouring pixel centres (an
/// anamorphic frame desqueezed for viewing; values per pixel are kept, not the flux). *outWidth gets
/// the new width.
std::vector<float> stretchedRows(const std::vector<float>& rgb, int width, int height, double factor, int* outWidth);

/// Preview tonemap of linear RGB (interleaved, 3 channels): multiply by 2^exposureEv, Reinhard
/// x / (1 + x) per channel, sRGB transfer curve, 8 bits.
std::vector<unsigned char> tonemapPreview(const std::vector<float>& rgb, double exposureEv);

/// Exposure (EV) that puts the 99th percentile of the non-zero pixels' largest channel at 1.0
/// (Reinhard 0.5): bright ghosts stay visible in previews of faint flares. 0 for a black image.
double autoExposure(const std::vector<float>& rgb);

void writePng(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb8,
              const Metadata& metadata);

} // namespace ff::image
