// libFuzzer target for the lens readers: every input is parsed as a native .lens file, as a Zemax
// .zmx file and as a pbrt .dat file (fuzz_lens.h: a lens or ff::Error, nothing else; a lens goes
// through first-order analysis and a writer round trip).

#include "fuzz_lens.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    for (const char* format : {"lens", "zmx", "dat"}) ff::fuzz::lensFormat(data, size, format);
    return 0;
}
