#pragma once
// Choosing the period, the number of terms and the route of every ghost (docs/fourier.md).
//
// Period: wide enough that no ghost's periodic copy reaches the frame (T >= max(x_k, W - x_k) + e_k
// and T >= 2 e_k, e_k its extent), rounded up to whole pixels of an FFT-friendly size. A ghost that
// would need a period beyond twice the frame (or the fixed period) is Wide: renderFourier puts the
// wide ghosts on a coarse level with a period of their own; one whose footprint misses the frame is
// culled.
// Terms: each ghost needs n_k = termsForError(width, T, budget) on x and m_k on y (the widest channel's
// need is the narrowest's). Among candidate N (with M = N Ty / Tx), the plan takes the one with the
// least estimated work: Fourier evaluation (two GEMMs per channel) + accumulation of the ghosts that
// fit + direct drawing of the others over their footprints (the hybrid). Every choice is recorded.

#include "fourier/ghost.h"

#include <memory>
#include <string>
#include <vector>

namespace ff::fourier {

class Backend; // backend.h

enum class Evaluation { Auto, Matrix, Fft };
const char* toString(Evaluation e);

/// How a group of ghosts is summed into the coefficients (aggregate.h): one GEMM of their
/// per-ghost coefficient vectors (K N M work), or spread onto a sampling grid of the period and
/// transformed once (gridded.h: K S^2 + G log G work, S the stencil, independent of N and M).
enum class Accumulation { Auto, Gemm, Grid };
const char* toString(Accumulation a);

/// Separable cosine/sine series on a rectangle (the default) or the radial Fourier-Bessel series
/// on a disc (bessel.h).
enum class Basis { Separable, Bessel };

struct FourierSettings {
    double error = 1e-3;                           ///< relative L2 budget per ghost
    int fixedN = 0;                                ///< > 0: use this N (x terms) instead of the budget's choice
    int fixedM = 0;                                ///< > 0: use this M (y terms); else N scaled by Ty / Tx
    double fixedPeriodX = 0.0, fixedPeriodY = 0.0; ///< > 0: use these periods (pixels)
    bool hybrid = true; ///< draw ghosts that need more terms directly; false: all go through Fourier
                        ///< (ghosts that would wrap into the frame still go to the coarse level)
    /// Accumulate each ghost only over the terms it needs for this fraction of the budget (0: all N x M).
    double trimFraction = 0.25;
    /// Largest period, as a multiple of the frame's larger side; ghosts needing more are Wide.
    double periodCap = 2.0;
    GaussianForm gaussianForm = GaussianForm::Periodised;
    bool dropDc = false; ///< zero the A_00 term (removes the mean: off by default, see docs)
    Evaluation evaluation = Evaluation::Auto;
    Accumulation accumulation = Accumulation::Auto; ///< Auto: per group, the one with less estimated work
    Basis basis = Basis::Separable;
    /// The device that draws the levels (backend.h); null: the CPU.
    std::shared_ptr<Backend> backend;
};

/// Wide: would wrap into the frame on this level's period; renderFourier gives these ghosts a coarse
/// level of their own (a larger period, few terms).
enum class Route : unsigned char { Fourier, Direct, Culled, Wide };

/// Ghosts of one shape summed together: on a GEMM, those that keep the same terms (bands of 8);
/// on a grid, those of one band and one width class (quarter octaves), keeping their own terms.
struct AccumulationGroup {
    Shape shape = Shape::Gaussian;
    int n = 0, m = 0; ///< terms kept, <= Plan::n, m (GEMM: the band)
    Accumulation method = Accumulation::Gemm;
    int gridX = 0, gridY = 0;            ///< Grid: samples per period on each axis
    double widestX = 0.0, widestY = 0.0; ///< the members' widest profile (any channel), pixels
    std::vector<std::size_t> members;    ///< ghost indices, ascending
};

struct Plan {
    Basis basis = Basis::Separable;
    double periodX = 0.0, periodY = 0.0; ///< pixels (Bessel: both the disc radius R0)
    int n = 0, m = 0;                    ///< terms per axis (Bessel: J radial, M angular); 0: nothing through Fourier
    int polarRings = 0, polarAngles = 0; ///< Bessel: the polar grid evaluated
    Evaluation evaluation = Evaluation::Matrix;
    std::vector<Route> route;              ///< per ghost
    std::vector<int> termsX, termsY;       ///< per ghost: terms accumulated (trimmed, <= n, m)
    std::vector<AccumulationGroup> groups; ///< the Fourier-routed ghosts by the terms they keep
    std::size_t fourier = 0, direct = 0, culled = 0, wide = 0;
    double estimatedGflop = 0.0;
    std::string reason; ///< how n and the period were chosen, in words

    /// One line for --verbose and the output metadata.
    std::string describe() const;
};

/// The plan for drawing `ghosts` into a width x height frame.
Plan choosePlan(const std::vector<Ghost>& ghosts, int width, int height, const FourierSettings& settings);

/// Groups the Fourier-routed ghosts of `plan` by shape and kept terms and chooses each group's
/// accumulation (choosePlan calls it last; accumulation_groups.cpp).
void groupForAccumulation(const std::vector<Ghost>& ghosts, const FourierSettings& settings, Plan& plan);

/// The next size >= n whose only prime factors are 2, 3 and 5.
int fftFriendly(int n);

} // namespace ff::fourier
