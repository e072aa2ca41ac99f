#include "cli/fourier_choices.h"

#include "cli/option_parsing.h"
#include "core/error.h"
#include "core/text.h"
#include "gpu/backend_choice.h"

#include <CLI/CLI.hpp>

#include <cstdio>

namespace ff::cli {

void FourierOptions::addTo(CLI::App& cmd) {
    errorOption = cmd.add_option("--fourier-error", error,
                                 "Relative L2 error budget: gaussian and cos2, per ghost (decides the period, N and "
                                 "the hybrid split); shaped (simulate), of the whole flare for the instances drawn "
                                 "through the Fourier series of a grid, default 1e-2 (docs/fourier.md)")
                      ->check(CLI::Range(1e-7, 0.5));
    cmd.add_option("--fourier-n", n,
                   "Use N terms along x (M follows the periods' ratio) instead of the budget's choice")
        ->check(CLI::Range(1, 2048));
    cmd.add_option("--fourier-period", period,
                   "Use the periods TX,TY in pixels (each at least the frame) instead of the automatic padding");
    cmd.add_option("--gaussian-form", gaussianForm,
                   "Gaussian coefficients: periodised, exact (truncated, complex erf) or as7126")
        ->check(CLI::IsMember({"periodised", "exact", "as7126"}));
    cmd.add_option("--evaluation", evaluation, "Series evaluation: auto, matrix (two GEMMs) or fft")
        ->check(CLI::IsMember({"auto", "matrix", "fft"}));
    cmd.add_option("--fourier-accumulation", accumulation,
                   "How ghosts are summed into the coefficients: auto (per group, the cheaper), gemm (per-ghost "
                   "coefficient vectors) or grid "
                   "(spread onto a sampling grid and transformed; docs/fourier.md)")
        ->check(CLI::IsMember({"auto", "gemm", "grid"}));
    cmd.add_flag("--drop-dc", dropDc, "Drop the A00 (mean) term, as early notes did; removes energy (docs/fourier.md)");
    cmd.add_option(
           "--fourier-basis", basis,
           "separable (cosine/sine on a rectangle) or bessel (radial Fourier-Bessel on a disc; Gaussian ghosts)")
        ->check(CLI::IsMember({"separable", "bessel"}));
    cmd.add_flag("--no-hybrid", noHybrid, "Send every ghost through Fourier, however many terms it needs");
    cmd.add_option("--backend", backend,
                   "Where the flare is drawn (the shaped ghosts' polygons or the Fourier series, and the diffraction's "
                   "convolution): cpu, gl (OpenGL 4.5 "
                   "compute through EGL; llvmpipe without a GPU) or auto (gl on a GPU, else cpu)")
        ->check(CLI::IsMember({"cpu", "gl", "auto"}));
}

namespace {

void note(const GlobalOptions& g, const std::string& s) {
    if (!g.quiet) std::fprintf(stderr, "fourierflare: note: %s\n", s.c_str());
}

} // namespace

fourier::FourierSettings FourierOptions::settings(const GlobalOptions& g) const {
    fourier::FourierSettings s;
    s.error = error;
    s.fixedN = n;
    if (!period.empty()) {
        const auto [tx, ty] = parsePair(period, ',', "--fourier-period TX,TY in pixels");
        if (!(tx >= 1.0) || !(ty >= 1.0) || tx > 1e6 || ty > 1e6)
            throw Error(ErrorKind::Usage,
                        "--fourier-period must be between 1 and 1e6 pixels, got " + text::quoted(period));
        s.fixedPeriodX = tx;
        s.fixedPeriodY = ty;
    }
    s.gaussianForm = gaussianForm == "exact"    ? fourier::GaussianForm::Exact
                     : gaussianForm == "as7126" ? fourier::GaussianForm::ErfAS7126
                                                : fourier::GaussianForm::Periodised;
    s.evaluation = evaluation == "matrix" ? fourier::Evaluation::Matrix
                   : evaluation == "fft"  ? fourier::Evaluation::Fft
                                          : fourier::Evaluation::Auto;
    s.accumulation = accumulation == "gemm"   ? fourier::Accumulation::Gemm
                     : accumulation == "grid" ? fourier::Accumulation::Grid
                                              : fourier::Accumulation::Auto;
    s.dropDc = dropDc;
    s.hybrid = !noHybrid;
    s.basis = basis == "bessel" ? fourier::Basis::Bessel : fourier::Basis::Separable;
    // The GL backend: required with gl; with auto, taken only where the renderer is not a software
    // rasteriser.
    std::string why;
    s.backend = gpu::openBackend(backend, why);
    if (!s.backend && backend == "auto") note(g, "--backend auto: no GPU (" + why + "), using the CPU");
    if (s.backend && g.verbose) note(g, "backend " + s.backend->describe());
    if (s.backend && s.basis == fourier::Basis::Bessel)
        note(g, "the Fourier-Bessel basis has no GL path: it runs on the CPU");
    return s;
}

} // namespace ff::cli
