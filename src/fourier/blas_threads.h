#pragma once
// OpenBLAS on one thread while a SingleThreadedBlas lives. ff_fourier runs its GEMMs as TBB tasks,
// each on the thread that calls it; OpenBLAS's own threads would only contend with TBB's (and they
// spin, yielding, for a while after each call). Internal to ff_fourier.

#include <cblas.h>

namespace ff::fourier {

class SingleThreadedBlas {
  public:
    SingleThreadedBlas() : previous_(openblas_get_num_threads()) { openblas_set_num_threads(1); }
    ~SingleThreadedBlas() { openblas_set_num_threads(previous_); }
    SingleThreadedBlas(const SingleThreadedBlas&) = delete;
    SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

  private:
    int previous_;
};

} // namespace ff::fourier
