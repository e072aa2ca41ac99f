// libFuzzer target for the pbrt .dat importer: a lens or ff::Error, nothing else; a lens it returns
// goes through first-order analysis and a writer round trip.

#include "fuzz_lens.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ff::fuzz::lensFormat(data, size, "dat");
    return 0;
}
