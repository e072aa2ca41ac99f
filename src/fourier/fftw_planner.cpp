#include "fourier/fftw_planner.h"

namespace ff::fourier {

std::mutex& fftwPlannerMutex() {
    static std::mutex m;
    return m;
}

} // namespace ff::fourier
