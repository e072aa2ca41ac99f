#include "trace/embree_device.h"

#include "core/error.h"

#include <tbb/global_control.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace ff::trace {

EmbreeDevice::EmbreeDevice() {
    // Embree builds on TBB within the process's parallelism limit (fourierflare --threads). Its
    // start_threads option is not used: it waits for every worker to join, which never happens under
    // a lower limit. Thread pinning (set_affinity=1) is not used either: with TBB it installs a
    // task-scheduler observer that Embree never releases (LeakSanitizer reports it), and pinning
    // gains nothing on machines shared with other work.
    const std::size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    device_ = rtcNewDevice(("threads=" + std::to_string(threads)).c_str());
    if (!device_)
        throwRuntimeError("cannot create an Embree device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
    rtcSetDeviceErrorFunction(device_, &EmbreeDevice::onError, this);
}

EmbreeDevice::~EmbreeDevice() {
    if (device_) rtcReleaseDevice(device_);
}

void EmbreeDevice::onError(void* user, RTCError code, const char* message) {
    auto* self = static_cast<EmbreeDevice*>(user);
    if (self->error_.empty())
        self->error_ = "Embree error " + std::to_string(static_cast<int>(code)) + ": " + (message ? message : "");
}

void EmbreeDevice::check(const char* what) {
    if (error_.empty()) return;
    const std::string e = error_;
    error_.clear();
    throwRuntimeError(std::string(what) + ": " + e);
}

void setFlushDenormalsToZero() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

} // namespace ff::trace
