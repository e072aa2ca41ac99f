#pragma once
// Where renderFourier's levels are drawn: the CPU (no backend) or a device that keeps the frame in its
// own memory from the first level to the read-back (gpu::GlBackend). renderFourier plans every level
// on the CPU and hands each to the backend: the accumulation of its Fourier ghosts, the evaluation of
// the series added to the frame, and the direct drawing of its small ghosts.

#include "fourier/plan.h"

#include <string>
#include <vector>

namespace ff::fourier {

struct StageSeconds {
    double plan = 0.0, accumulate = 0.0, evaluate = 0.0, direct = 0.0;
    double total() const { return plan + accumulate + evaluate + direct; }
};

class Backend {
  public:
    virtual ~Backend() = default;
    /// The device in words (for --verbose and the output metadata).
    virtual std::string describe() const = 0;
    /// Starts a frame: width x height, all zero.
    virtual void begin(int width, int height) = 0;
    /// Adds one level (ghosts and their routes in plan) to the frame; stage times go to seconds.
    virtual void addLevel(const std::vector<Ghost>& ghosts, const Plan& plan, const FourierSettings& settings,
                          StageSeconds& seconds) = 0;
    /// Reads the frame back (image is resized to it).
    virtual void finish(FlareImage& image) = 0;
};

} // namespace ff::fourier
