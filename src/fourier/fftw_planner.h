#pragma once
// FFTW's planner (plan creation and destruction) is not thread-safe; executing an existing plan on new
// arrays is. Every plan of ff_fourier is made and destroyed under this one lock. Internal.

#include <mutex>

namespace ff::fourier {

std::mutex& fftwPlannerMutex();

} // namespace ff::fourier
