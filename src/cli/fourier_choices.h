#pragma once
// The aggregator's options as `render` and `compare` accept them, and the ghosts of a scene.

#include "cli/console.h"
#include "cli/trace_choices.h"
#include "diffraction/convolution.h"
#include "fourier/plan.h"
#include "ghosts/instancing.h"
#include "ghosts/shaped_ghosts.h"

#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
} // namespace CLI

namespace ff::cli {

struct FourierOptions {
    double error = 1e-3;
    int n = 0;
    std::string period; ///< "TX,TY" pixels
    std::string gaussianForm = "periodised";
    std::string evaluation = "auto";
    std::string accumulation = "auto"; ///< auto, gemm or grid
    bool dropDc = false;
    bool noHybrid = false;
    std::string basis = "separable";
    std::string backend = "auto";       ///< cpu, gl or auto
    CLI::Option* errorOption = nullptr; ///< --fourier-error (given: count() > 0)

    void addTo(CLI::App& cmd);
    /// The settings, with the GL backend made when --backend asks for it: gl without an OpenGL 4.5
    /// context throws ff::Error (Runtime); auto takes a hardware device only, else notes the fall-back.
    fourier::FourierSettings settings(const GlobalOptions& g) const;
};

} // namespace ff::cli
