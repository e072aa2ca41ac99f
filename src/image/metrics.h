#pragma once
// Comparing two linear RGB images (interleaved, 3 channels, same size): the numbers `compare`
// reports, and a signed false-colour picture of their difference.

#include <vector>

namespace ff::image {

struct ImageError {
    double relativeL2 = 0.0;  ///< ||a - ref|| / ||ref|| over all channels and pixels
    double psnrDb = 0.0;      ///< 20 log10(max |ref| / RMS(a - ref)); +inf when identical
    double maxAbs = 0.0;      ///< largest |a - ref| over channels and pixels
    double maxRelative = 0.0; ///< maxAbs / max |ref|
    double fluxRatio = 0.0;   ///< sum a / sum ref (all channels)
};

ImageError compareImages(const std::vector<float>& a, const std::vector<float>& reference);

/// Signed difference of the luminances (Rec. 709 weights) of a and reference as 8-bit RGB: white where
/// they agree, red where a is brighter, blue where it is darker, full colour at |difference| >= scale.
std::vector<unsigned char> differencePicture(const std::vector<float>& a, const std::vector<float>& reference,
                                             double scale);

/// The luminance difference's q-quantile of |a - reference| (q in [0, 1]), a scale for the picture.
double differenceQuantile(const std::vector<float>& a, const std::vector<float>& reference, double q);

} // namespace ff::image
