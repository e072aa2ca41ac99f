#pragma once
// RAII ownership of an Embree 3 device. Embree reports errors through a callback; this one records
// the first message so the owner can turn it into an ff::Error after the call that failed.

#include <embree3/rtcore.h>

#include <string>

namespace ff::trace {

class EmbreeDevice {
  public:
    EmbreeDevice();
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    RTCDevice get() const { return device_; }
    /// Throws ff::Error (Runtime) if Embree reported an error since the last check, naming `what`.
    void check(const char* what);

  private:
    static void onError(void* user, RTCError code, const char* message);
    RTCDevice device_ = nullptr;
    std::string error_;
};

/// Flush denormals to zero for the calling thread (Embree's recommendation for speed).
void setFlushDenormalsToZero();

} // namespace ff::trace
