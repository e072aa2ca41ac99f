#pragma once
// All lights' diffraction at once: the image of the light sources convolved with the PSF by FFT (one
// transform per channel, any number of lights), and the diffraction layer simulate adds.

#include "diffraction/psf.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace ff::diffraction {

/// Where the convolution runs when not on the CPU (FFTW): the GL backend's compute-shader FFT.
class Convolver {
  public:
    virtual ~Convolver() = default;
    /// As diffraction::convolve.
    virtual std::vector<float> convolve(const std::vector<float>& image, int width, int height, const Psf& psf,
                                        double* offFrame) = 0;
};

/// The convolution on the CPU (FFTW), as convolve, keeping the transforms' plans and the kernel's
/// spectra of the last frame for the next frame of the same size and PSF whose lights need the same
/// periods (a shot's frames: each transforms only its lights; about 150 MB kept at 1080p).
class FftwConvolver final : public Convolver {
  public:
    FftwConvolver();
    ~FftwConvolver() override;
    FftwConvolver(const FftwConvolver&) = delete;
    FftwConvolver& operator=(const FftwConvolver&) = delete;
    std::vector<float> convolve(const std::vector<float>& image, int width, int height, const Psf& psf,
                                double* offFrame) override;

  private:
    struct Kept;
    std::unique_ptr<Kept> kept_;
};

/// image (R, G, B interleaved, width x height) convolved with the PSF's channels (linear, not
/// circular: zero outside the frame; the kernel with its far field reaching from the lights to the
/// frame's far edges, frameKernel): by FFT, or by adding the kernel at each non-zero pixel where
/// there are so few that this costs less (the same values up to the transforms' rounding). The flux the kernel carries
/// beyond the frame is added to *offFrame (summed over the channels) when given.
std::vector<float> convolve(const std::vector<float>& image, int width, int height, const Psf& psf,
                            double* offFrame = nullptr);

/// Channel c of the PSF over the offsets |dx| <= rx, |dy| <= ry ((2 rx + 1) x (2 ry + 1), rows down):
/// the kernel's square, and beyond it the far field. *total is the channel's flux to any distance:
/// 1 with a far field (what lies beyond rx, ry leaves the frame), the square's sum without.
std::vector<float> frameKernel(const Psf& psf, int c, int rx, int ry, double* total = nullptr);

/// Adds to `out` (R, G, B interleaved, width x height) flux[c] times channel c of convolve's kernel
/// centred on the pixel (x, y) outside the frame: the PSF of the part of a light that falls outside
/// it, reaching in (the square near (x, y), the far field beyond). convolve of the image holding
/// the light at (x, y) on a frame large enough to hold it, seen through this frame. The flux it
/// carries beyond the frame is added to *offFrame (summed over the channels) when given. One pass
/// over the frame's pixels (where a far field reaches it; those near (x, y) without one).
void addOutsideLight(const Psf& psf, long long x, long long y, const std::array<double, 3>& flux, int width, int height,
                     std::vector<float>& out, double* offFrame = nullptr);

/// A 64-bit hash (FNV-1a) of everything the kernel is made from (the square, the far field): equal
/// fingerprints, equal kernels. Keys a convolver's cached transform of the kernel across frames.
std::uint64_t kernelFingerprint(const Psf& psf);

/// How far (x, y) convolve's kernel reaches: the PSF's square without a far field; with one, from the
/// image's non-zero pixels to the frame's far edges.
std::array<int, 2> kernelReach(const std::vector<float>& image, int width, int height, const Psf& psf);

/// Whether convolve adds the kernel at each of image's non-zero values (R, G and B counted apart)
/// rather than transforming.
bool convolvesDirectly(const std::vector<float>& image, int width, int height, const Psf& psf);

/// The diffraction layer of the light sources `lights` (R, G, B interleaved; the part of the plate
/// that is the lights' sharp image): gain x (lights * PSF - lights), the lights' flux spread into
/// the pattern and taken from the pixels that held it, so it sums to zero (less what leaves the
/// frame). Where a gain above 1 would take more than a pixel's light from it, it takes that light.
/// The convolution runs on `device` when one is given.
std::vector<float> diffractionLayer(const std::vector<float>& lights, int width, int height, const Psf& psf,
                                    double gain, double* offFrame = nullptr, Convolver* device = nullptr);

/// The lights split over a tilesX x tilesY grid of the frame (where the PSF changes over it: the
/// lens's wavefront at each light's field): part(tile, x, y) for each tile that holds light, with the
/// image of that tile's lights alone (the rest zero) and their flux-weighted centre (pixels from the
/// frame's top-left corner, summed over the channels); the parts summed, tile by tile, rows first.
/// Tiles without light cost nothing.
std::vector<float>
sumOverTiles(const std::vector<float>& lights, int width, int height, int tilesX, int tilesY,
             const std::function<std::vector<float>(const std::vector<float>& tile, double x, double y)>& part);

} // namespace ff::diffraction
