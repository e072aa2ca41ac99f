#pragma once
// Loads a lens file of any supported format, chosen by extension: .lens (native), .zmx (Zemax),
// .dat (pbrt). The file is read once, size-checked before reading, and never modified.

#include "core/reporter.h"
#include "optics/lens.h"

#include <filesystem>

namespace ff::optics {

/// Largest lens file accepted (bytes); real prescriptions are a few kB.
inline constexpr std::uintmax_t kMaxLensFileBytes = 4u << 20;

Lens loadLens(const std::filesystem::path& path, Reporter* reporter = nullptr);

/// The lens file `nameOrPath` names: the path itself when it is a file; else, for a bare name
/// (no '/'), <folder>/<name> or <folder>/<name>.lens in each folder of ff::lensSearchPath() (the
/// installed bundled lenses last; docs/install.md). Throws ff::Error (Input) saying where it looked.
std::filesystem::path findLensFile(const std::string& nameOrPath);

/// Parses lens bytes of the given format ("lens", "zmx", "dat"); fileName for messages.
Lens parseLensBytes(std::string_view bytes, const std::string& format, const std::string& fileName,
                    Reporter* reporter = nullptr);

/// Throws ff::Error (Input, naming the file) for a lens the ghost tables, their fits and the traced
/// wavefront cannot take: one with anamorphic surfaces (scene::requireLensFor says what takes those).
void requireTraceable(const Lens& lens);

/// The lens at the zoom position `zoom` (a label or 1-based index; "" = as loaded).
Lens loadLensAt(const std::filesystem::path& path, const std::string& zoom, Reporter* reporter = nullptr);

/// The lens at the zoom position `zoom` (a label or 1-based index; "" = as loaded), refusing an
/// anamorphic lens, which the ghost tracer cannot trace (ff::Error, Input, naming the file).
Lens loadTraceableLens(const std::filesystem::path& path, const std::string& zoom, Reporter* reporter = nullptr);

} // namespace ff::optics
