// The table as `fourierflare table` and `simulate --ghost-model gaussian` get it: cold (the shaped
// meshes traced, the fits derived, the entry written to an empty cache) and warm (the entry's header
// read), for the double Gauss 50 mm, the Nikon 28-75 mm at 28 mm and the zoom 70-200 mm at 70 mm.
// The shaped table as `simulate` gets it warm (the whole entry read: header, meshes decompressed and
// decoded, into memory the process has not touched before). Baseline: the warm read of the double Gauss's header.

#include "core/file_io.h"
#include "core/reporter.h"
#include "ghosts/shaped_cache.h"
#include "optics/lens_loader.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <malloc.h>
#include <optional>
#include <string>

using namespace ff;

namespace {

optics::Lens lensAt(const char* file) {
    return optics::loadLens(std::string(FF_SOURCE_DIR) + "/lenses/" + file);
}

// A cache folder of the bench's own, empty at the start of the run.
std::filesystem::path cacheFolder() {
    static const std::filesystem::path dir = [] {
        const auto d = std::filesystem::temp_directory_path() / "fourierflare-bench-table";
        std::filesystem::remove_all(d);
        std::filesystem::create_directories(d);
        setenv("FF_CACHE_DIR", d.c_str(), 1);
        return d;
    }();
    return dir;
}

void cold(benchmark::State& state, const char* file) {
    const optics::Lens lens = lensAt(file);
    const ghosts::TableSettings s;
    cacheFolder();
    CollectingReporter rep;
    std::size_t entries = 0;
    for (auto _ : state) {
        std::filesystem::remove_all(ff::cacheDirectory());
        bool cached = true;
        const ghosts::GhostTable t = ghosts::tableFor(lens, s, true, {}, rep, &cached);
        entries = t.entryCount();
        if (cached) state.SkipWithError("the cache was not empty");
    }
    state.counters["ghosts x angles"] = double(entries);
    std::uintmax_t bytes = 0;
    for (const auto& e : std::filesystem::directory_iterator(ff::cacheDirectory())) bytes += e.file_size();
    state.counters["entry_MB"] = double(bytes) / 1e6;
}

void warm(benchmark::State& state, const char* file) {
    const optics::Lens lens = lensAt(file);
    const ghosts::TableSettings s;
    cacheFolder();
    CollectingReporter rep;
    ghosts::tableFor(lens, s, true, {}, rep); // built once if missing
    for (auto _ : state) {
        bool cached = false;
        const ghosts::GhostTable t = ghosts::tableFor(lens, s, true, {}, rep, &cached);
        benchmark::DoNotOptimize(t.ghosts.data());
        if (!cached) state.SkipWithError("the entry was not read from the cache");
    }
}

void shapedWarm(benchmark::State& state, const char* file) {
    const optics::Lens lens = lensAt(file);
    const ghosts::TableSettings s;
    cacheFolder();
    CollectingReporter rep;
    ghosts::shapedTableFor(lens, s, true, rep); // built once if missing
    std::size_t bytes = 0;
    for (auto _ : state) {
        bool cached = false;
        std::optional<ghosts::ShapedTable> t = ghosts::shapedTableFor(lens, s, true, rep, &cached);
        bytes = t->bytes();
        if (!cached) state.SkipWithError("the entry was not read from the cache");
        // Freed and handed back to the kernel outside the timing: each read, like simulate's one,
        // faults its pages in afresh instead of reusing the last one's (glibc keeps freed memory).
        state.PauseTiming();
        t.reset();
        malloc_trim(0);
        state.ResumeTiming();
    }
    state.counters["mesh_MB"] = double(bytes) / 1e6;
}

void BM_TableWarm_DoubleGauss_Baseline(benchmark::State& s) {
    warm(s, "double-gauss-50mm-f2.lens");
}
void BM_TableCold_DoubleGauss(benchmark::State& s) {
    cold(s, "double-gauss-50mm-f2.lens");
}
void BM_ShapedWarm_DoubleGauss(benchmark::State& s) {
    shapedWarm(s, "double-gauss-50mm-f2.lens");
}
void BM_ShapedWarm_Nikon(benchmark::State& s) {
    shapedWarm(s, "nikon-28-75mm-at-28mm.lens");
}
void BM_ShapedWarm_Zoom(benchmark::State& s) {
    shapedWarm(s, "zoom-70-200mm-f2.8.lens");
}
void BM_TableWarm_Nikon(benchmark::State& s) {
    warm(s, "nikon-28-75mm-at-28mm.lens");
}
void BM_TableCold_Nikon(benchmark::State& s) {
    cold(s, "nikon-28-75mm-at-28mm.lens");
}
void BM_TableWarm_Zoom(benchmark::State& s) {
    warm(s, "zoom-70-200mm-f2.8.lens");
}
void BM_TableCold_Zoom(benchmark::State& s) {
    cold(s, "zoom-70-200mm-f2.8.lens");
}

} // namespace

BENCHMARK(BM_TableWarm_DoubleGauss_Baseline)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShapedWarm_DoubleGauss)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShapedWarm_Nikon)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShapedWarm_Zoom)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TableCold_DoubleGauss)->Iterations(2)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_TableWarm_Nikon)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TableCold_Nikon)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_TableWarm_Zoom)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TableCold_Zoom)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

BENCHMARK_MAIN();
