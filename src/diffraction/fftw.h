#pragma once
// Double-precision FFTW arrays and plans for the diffraction stage. Plans are made and destroyed under
// ff_fourier's planner lock (FFTW's planner is not thread-safe; executing a plan on new arrays is).
// Internal.

#include "core/error.h"
#include "fourier/fftw_planner.h"

#include <cstddef>
#include <fftw3.h>
#include <memory>
#include <mutex>

namespace ff::diffraction {

/// The smallest size >= n whose factors are 2, 3, 5 and 7 (FFTW's fast sizes).
inline int fastSize(int n) {
    for (int m = n < 1 ? 1 : n;; ++m) {
        int r = m;
        for (int f : {2, 3, 5, 7})
            while (r % f == 0) r /= f;
        if (r == 1) return m;
    }
}

template <typename T>
using FftwArray = fourier::FftwDoubleArray<T>;

/// `count` elements from fftw_malloc (uninitialised); throws ff::Error (Runtime) when out of memory.
template <typename T>
FftwArray<T> fftwArray(std::size_t count) {
    auto a = fourier::fftwDoubleArray<T>(count);
    if (!a) throw Error(ErrorKind::Runtime, "out of memory for the diffraction's transforms");
    return a;
}

struct Plan {
    fftw_plan plan = nullptr;
    /// make() returns the plan (FFTW_ESTIMATE: the arrays are not touched); throws when it is null.
    template <typename Make>
    explicit Plan(Make make) {
        std::lock_guard<std::mutex> lock(fourier::fftwPlannerMutex());
        plan = make();
        if (!plan) throw Error(ErrorKind::Runtime, "FFTW could not plan a diffraction transform");
    }
    ~Plan() {
        std::lock_guard<std::mutex> lock(fourier::fftwPlannerMutex());
        fftw_destroy_plan(plan);
    }
    Plan(const Plan&) = delete;
    Plan& operator=(const Plan&) = delete;
};

} // namespace ff::diffraction
