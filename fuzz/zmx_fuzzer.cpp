// libFuzzer target for the Zemax .zmx importer (UTF-8 and UTF-16 files, GRADIENT surfaces): it may
// only return a lens or throw ff::Error. A lens it returns goes through first-order analysis and
// the .lens writer, whose output must parse again.

#include "fuzz_lens.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ff::fuzz::lensFormat(data, size, "zmx");
    return 0;
}
