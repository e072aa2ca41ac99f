#pragma once
// Writing an image through OpenImageIO to a temporary file in the target's folder, then renaming it:
// a failed write never leaves a partial or corrupted output. Internal to ff_image.

#include <OpenImageIO/imageio.h>

#include <string>

namespace ff::image {

/// Writes `data` (laid out as `type` says, TypeUnknown = the spec's native per-channel formats) with
/// `spec`, atomically. Throws ff::Error (Runtime) naming `path`.
void writeAtomic(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type, const void* data);

} // namespace ff::image
