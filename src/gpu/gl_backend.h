#pragma once
// The OpenGL backend of the Fourier renderer: each level's accumulation (accumulate.comp), evaluation
// (evaluate_rows.comp, evaluate_pixels.comp) and direct drawing (direct_draw.comp) on the GPU, the
// frame kept in GPU memory from the first level to the read-back, and compositing onto the plate
// (composite.comp) from that same frame.

#include "fourier/backend.h"
#include "gpu/gl_accumulator.h"
#include "gpu/gl_composite.h"
#include "gpu/gl_context.h"
#include "gpu/gl_direct.h"
#include "gpu/gl_evaluator.h"
#include "gpu/gl_fft.h"
#include "gpu/gl_polygon_raster.h"

#include <memory>

namespace ff::gpu {

class GlBackend final : public fourier::Backend {
  public:
    explicit GlBackend(std::unique_ptr<GlContext> context);
    ~GlBackend() override;

    std::string describe() const override;
    void begin(int width, int height) override;
    void addLevel(const std::vector<fourier::Ghost>& ghosts, const fourier::Plan& plan,
                  const fourier::FourierSettings& settings, fourier::StageSeconds& seconds) override;
    void finish(fourier::FlareImage& image) override;

    /// plate + the last frame (R, G, B interleaved, the frame's size); see GlCompositor.
    std::vector<float> composite(const std::vector<float>& plate);
    int maxCompositeSide() const { return compositor_->maxSide(); }
    /// The shaped ghosts' polygon raster on this backend's context (made on first use).
    GlPolygonRaster& polygonRaster();
    /// The diffraction's FFT convolution on this backend's context (made on first use).
    GlFft& fft();
    const GlContext& context() const { return *context_; }

  private:
    std::unique_ptr<GlContext> context_;
    std::unique_ptr<GlAccumulator> accumulator_;
    std::unique_ptr<GlEvaluator> evaluator_;
    std::unique_ptr<GlDirect> direct_;
    std::unique_ptr<GlCompositor> compositor_;
    std::unique_ptr<GlPolygonRaster> polygons_;
    std::unique_ptr<GlFft> fft_;
    Buffer z_, image_;
    int width_ = 0, height_ = 0;
};

} // namespace ff::gpu
