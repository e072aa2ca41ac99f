#pragma once
// Two-dimensional complex FFTs in double precision on the GPU — radix-2 Stockham passes ping-ponging
// between two buffers (shaders/fft_pass.comp), twiddles computed on the host — and the diffraction
// stage's convolution with them: each channel of the lights' image and of the PSF transformed,
// multiplied (shaders/spectrum_product.comp) and transformed back, as diffraction::convolve does with
// FFTW.

#include "diffraction/convolution.h"
#include "gpu/gl_context.h"
#include "gpu/gl_objects.h"

#include <complex>
#include <memory>
#include <vector>

namespace ff::gpu {

class GlFft final : public diffraction::Convolver {
  public:
    explicit GlFft(const GlContext& context);
    ~GlFft() override;

    /// The 2-D DFT of a width x height complex array (row-major; both sizes powers of 2, at most
    /// 16384): forward with exp(-i ...), or inverse with exp(+i ...), unnormalised.
    std::vector<std::complex<double>> transform(const std::vector<std::complex<double>>& data, int width, int height,
                                                bool inverse);

    std::vector<float> convolve(const std::vector<float>& image, int width, int height, const diffraction::Psf& psf,
                                double* offFrame) override;

  private:
    // Transforms *data (width x height, on the GPU) in place, using *scratch.
    void transform(std::unique_ptr<Buffer>& data, std::unique_ptr<Buffer>& scratch, int width, int height,
                   bool inverse);
    void twiddles(int length);

    std::unique_ptr<ComputeProgram> pass_, product_;
    Buffer twiddle_;
    int twiddleLength_ = 0;
    std::unique_ptr<Buffer> a_, b_, scratch_;
};

} // namespace ff::gpu
