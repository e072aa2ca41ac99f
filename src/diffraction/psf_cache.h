#pragma once
// The aberration-free PSF on disk, beside the ghost tables (ff::cacheDirectory()): a warm run pays
// only the convolution. Keyed by everything pixelPsf reads: the iris (blades, rotation), the working
// f-number, the pixel pitch, the wavelengths, the transform and the dirt (PupilMask::key), with the
// format's version. A missing entry is computed and stored (atomically); an unreadable, corrupt or
// mismatching one is recomputed with a note, never trusted.
//
// Format: the magic "FFPSF\0\0\0", a 32-bit format version, the key's length (64 bits) and text, the
// radius (32 bits), Psf::outside and Psf::edge (doubles), the wavelengths' count (32 bits), each
// wavelength (double) and its binning (32 bits), the three channels' (2 radius + 1)^2 floats, the
// far field (FarField::airy's three doubles; the lines' count (32 bits), each line's nx, ny, step
// (doubles), half (32 bits) and per channel its 2 half + 1 profile doubles), and the
// CRC-32 of everything before it. Little-endian, as the machine writes it.

#include "core/reporter.h"
#include "diffraction/psf.h"

#include <string>
#include <string_view>

namespace ff::diffraction {

/// The key of pixelPsf(aperture, settings) (settings without a pupil function).
std::string psfCacheKey(const Aperture& aperture, const PsfSettings& settings);

std::string psfToBytes(const Psf& psf, const std::string& key);
/// A PSF from psfToBytes; throws Error (Input, naming `file`) unless the bytes are a complete, intact
/// entry of this format version. `key` is set to the entry's key.
Psf psfFromBytes(std::string_view bytes, const std::string& file, std::string& key);

/// pixelPsf(aperture, settings), from the cache when a valid entry with its key exists, else
/// computed (and stored when useCache). Settings with a pupil function (a traced wavefront) are
/// always computed. `fromCache` tells which happened.
Psf cachedPixelPsf(const Aperture& aperture, const PsfSettings& settings, bool useCache, Reporter& reporter,
                   bool* fromCache = nullptr);

} // namespace ff::diffraction
