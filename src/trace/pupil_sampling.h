#pragma once
// Pupil sampling for a light source at infinity (the ray bundles themselves: trace/bundle.h).
//
// Sampling:
//  - ParaxialGrid: the grid covers the square circumscribing the paraxial entrance pupil, centred on
//    the axis for every field angle; rays outside the pupil disc are not launched.
//  - Reaim (default): a coarse pass, refined locally, finds where light actually gets through along
//    the given path (the real, vignetted pupil of that path at this field angle) and the grid covers
//    that region's bounding box, so every path gets its full resolution.
// Every launched ray stands for one grid cell of area cellArea (mm^2 in the pupil plane), so path
// energies are sums of weight x cellArea and compare across bundles.

#include "trace/bundle.h"
#include "trace/embree_tracer.h"
#include "trace/pupil_region.h"

#include <glm/vec2.hpp>

#include <span>
#include <vector>

namespace ff::trace {

enum class Sampling { Reaim, ParaxialGrid };

/// Where the grid of one path goes, by the chosen sampling. For Reaim, a coarse analytic pass at L's
/// wavelength (jittered points an eighth of the pupil radius apart, up to 512 across, so that small
/// patches and thin rings of light are not stepped over), then local passes over what it found (until
/// no light reaches their outermost points), so that the region moves smoothly with the field angle;
/// its margin (1/96 of the coarse square) also covers the small shift of the pupil with wavelength, so
/// one region serves every wavelength of a path (where the lit shape changes with it, search at each). What
/// the coarse pass finds is completed by the light's mirror symmetry across the line through the axis
/// along the field's azimuth, where the iris is symmetric about that line (Iris::mirrorSymmetricAbout).
/// With maxRadiusMm > 0 only light landing within that radius of the axis counts as found: where the
/// rest of a ghost is not measured, its grid need not cover it.
PupilRegion pupilRegion(const PupilFrame& frame, const Field& field, Sampling sampling, const LensAtWavelength& L,
                        const std::vector<PathStep>& steps, double maxRadiusMm = 0.0);

/// One region for a band of wavelengths, for callers that trace all of them on the same grid: the
/// square over the regions searched at the band's shortest and longest wavelengths (first and last
/// of `ends`). A lit pupil can change shape with the wavelength, not only shift, and the indices,
/// which move its edges, change monotonically across a band; its lit fraction is the larger lit
/// area's share of that square, its thin share the larger one, its lit points both searches'.
PupilRegion bandRegion(const PupilFrame& frame, const Field& field, Sampling sampling,
                       std::span<const LensAtWavelength> ends, const std::vector<PathStep>& steps,
                       double maxRadiusMm = 0.0);

} // namespace ff::trace
