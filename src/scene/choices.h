#pragma once
// The choices a flare request makes, as types: the CLI and the Python module parse their strings
// into these once (named), and write them back (toString) into files' headers and summaries.

#include <string_view>

namespace ff::scene {

/// How `render` draws (docs/cli.md): every ghost ray-traced, the shaped ghosts' meshes, the table's
/// fits drawn directly or aggregated through the Fourier series, or the iris's diffraction alone.
enum class RenderMode { Traced, Shaped, Fitted, Fourier, Diffraction };

/// What `simulate` draws the ghosts with: their traced meshes or the table's fitted profiles.
enum class GhostModel { Shaped, Gaussian, Cos2 };

/// The iris's diffraction: none, the aberration-free PSF, or each light's own PSF with the lens's
/// traced wavefront.
enum class DiffractionRule { Off, Physical, Traced };

const char* toString(RenderMode m);
const char* toString(GhostModel m);
const char* toString(DiffractionRule r);

/// The choice a name spells (toString's names). Throws ff::Error (Usage) naming `what` (the option
/// or argument) and the names it takes.
RenderMode renderModeNamed(std::string_view name, std::string_view what = "the render mode");
GhostModel ghostModelNamed(std::string_view name, std::string_view what = "the ghost model");
DiffractionRule diffractionNamed(std::string_view name, std::string_view what = "the diffraction");

} // namespace ff::scene
