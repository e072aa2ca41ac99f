#pragma once
// What ff_fourier's FFTW users share. FFTW's planner (plan creation and destruction) is not
// thread-safe; executing an existing plan on new arrays is: every plan of ff_fourier is made and
// destroyed under one lock. Arrays come from fftwf_malloc (the alignment plans expect) and are owned
// by FftwArray. Internal.

#include <cstddef>
#include <fftw3.h>
#include <memory>
#include <mutex>

namespace ff::fourier {

std::mutex& fftwPlannerMutex();

template <void (*Free)(void*)>
struct FftwFree {
    void operator()(void* p) const { Free(p); }
};
template <typename T>
using FftwArray = std::unique_ptr<T, FftwFree<fftwf_free>>;
template <typename T>
using FftwDoubleArray = std::unique_ptr<T, FftwFree<fftw_free>>; ///< for the double-precision library

/// `count` elements from fftwf_malloc (uninitialised; null when out of memory).
template <typename T>
FftwArray<T> fftwArray(std::size_t count) {
    return FftwArray<T>(static_cast<T*>(fftwf_malloc(sizeof(T) * count)));
}
/// `count` elements from fftw_malloc (uninitialised; null when out of memory).
template <typename T>
FftwDoubleArray<T> fftwDoubleArray(std::size_t count) {
    return FftwDoubleArray<T>(static_cast<T*>(fftw_malloc(sizeof(T) * count)));
}

} // namespace ff::fourier
