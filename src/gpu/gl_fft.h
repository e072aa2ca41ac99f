#pragma once
// Two-dimensional complex FFTs in double precision on the GPU — mixed-radix (4, 2, 3) Stockham passes
// ping-ponging between two buffers (shaders/fft_pass.comp), twiddles computed on the host — over
// periods of 2^a 3^b, and the diffraction
// stage's convolution with them: the lights' red and green laid into the period on the GPU as one
// complex image r + i g (shaders/fft_scatter.comp), transformed, each channel's spectrum multiplied
// by its kernel's (shaders/spectrum_product.comp), transformed back, the two convolutions read out
// of the real and imaginary parts (shaders/fft_gather.comp); then blue alone; as diffraction::convolve
// does with FFTW. The rows beyond the frame are skipped where they hold zeros or are not wanted. The kernel's three
// spectra stay on the GPU for the next frame of the same size and PSF (a shot's frames transform only their lights).

#include "diffraction/convolution.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <array>
#include <complex>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

namespace ff::gpu {

class GlFft final : public diffraction::Convolver {
  public:
    explicit GlFft(const GlContext& context);
    ~GlFft() override;

    /// The 2-D DFT of a width x height complex array (row-major; both sizes of the form 2^a 3^b, at
    /// most 16384): forward with exp(-i ...), or inverse with exp(+i ...), unnormalised.
    std::vector<std::complex<double>> transform(const std::vector<std::complex<double>>& data, int width, int height,
                                                bool inverse);

    std::vector<float> convolve(const std::vector<float>& image, int width, int height, const diffraction::Psf& psf,
                                double* offFrame) override;

  private:
    // Transforms *data (width x height, on the GPU) in place, using *scratch. Forward, only the
    // first `used` rows hold data (the rest are taken as zero); inverse, only the first `used` rows
    // of the result are made (0: all rows).
    void transform(std::unique_ptr<Buffer>& data, std::unique_ptr<Buffer>& scratch, int width, int height, bool inverse,
                   int used = 0);
    /// exp(-2 pi i q / length) for q < length, made once per length.
    const Buffer& twiddles(int length);

    // Channel c's kernel spectrum for frames of width x height over a period x rows period.
    void kernelSpectra(const diffraction::Psf& psf, int width, int height, int period, int rows);
    void dispatch(std::size_t invocations) const;

    std::unique_ptr<ComputeProgram> pass_, product_, scatter_, gather_;
    Buffer image_, frame_;
    std::map<int, std::unique_ptr<Buffer>> twiddles_;
    std::unique_ptr<Buffer> a_, scratch_;
    /// What the cached spectra were made for: the PSF's fingerprint, the frame's and the period's sizes.
    struct KernelKey {
        std::uint64_t psf = 0;
        int width = 0, height = 0, period = 0, rows = 0;
        bool operator==(const KernelKey&) const = default;
    };
    KernelKey key_;
    std::array<std::unique_ptr<Buffer>, 3> spectrum_;
    std::array<double, 3> flux_{}; ///< each channel's kernel flux to any distance (frameKernel's total)
};

} // namespace ff::gpu
