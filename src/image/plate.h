#pragma once
// HDR plates: reading any image OpenImageIO reads, defensively, and writing the simulated result with
// every input channel unchanged.
//
// Reading is guarded twice. A plate's header is checked against limits (pixels, channels, deep data)
// before anything is allocated. And because a corrupt file can crash or hang the image library itself
// (Debian's OpenImageIO 2.4 aborts or hangs on some fuzzed EXR files), the file is first read in full
// by a fresh process (the `checker` program, given the file and the limits, which calls checkPlate()
// under a memory limit) with bounds on its CPU and wall-clock time (PlateLimits); only if that
// succeeds is it read here. A crash, a loop or an error in the checker becomes an ff::Error (Input)
// naming the file; a checker stuck without spending CPU time, an ff::Error (Runtime). (A fresh
// process, not a fork: a forked child inherits the image library's thread pools without their
// threads and can hang.)

#include "image/image_output.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ff::image {

/// The default CPU bound of a plate's header check (PlateLimits::cpuSeconds), in seconds; the
/// environment variable FF_PLATE_CHECK_SECONDS sets another (plateCheckSeconds()).
inline constexpr double kPlateCheckSeconds = 3.0;

struct PlateLimits {
    std::uint64_t maxPixels = 8192ull * 8192ull; ///< data-window pixels
    int maxChannels = 64;
    /// The guarded read's bounds, in two stages: to start, open the file and pass the header checks;
    /// then to read the pixels, whose size as float the header declares (within the limits above).
    /// The checker's CPU time (user + system, all its threads) may grow by `cpuSeconds` in the first
    /// stage and by `cpuSeconds` plus one second per `floatBytesPerSecond` in the second: a loop in
    /// the image library runs out of it whatever the load, while a valid file that is slow only
    /// because the machine is busy waits for a core without spending it. Each stage's wall-clock
    /// time is bounded by `wallFactor` times its CPU bound, for a checker stuck without spending CPU
    /// time (blocked on a lock, or on a file system that does not answer).
    double cpuSeconds = kPlateCheckSeconds;
    double floatBytesPerSecond = 25e6;
    double wallFactor = 20.0;
    /// The checker: run as `checker plate-check --max-pixels N --max-channels C FILE`; empty = no guard.
    /// The CLI gives itself, kThisProgram.
    std::string checker;
    /// Called once the header has passed the checks, with the pixels' size as float in bytes (the
    /// checker process reports it to the guard on its standard output, see checkPlate()).
    void (*onHeader)(std::uint64_t floatBytes) = nullptr;
};

/// The CPU bound of the plate checks, PlateLimits::cpuSeconds: FF_PLATE_CHECK_SECONDS where it is set
/// (a number of seconds, 0.1 to 86400), else kPlateCheckSeconds. Throws ff::Error (Usage) naming the
/// variable for any other value.
double plateCheckSeconds();

/// The running program, as a checker path: the kernel's link to its file, which exec follows even
/// after the file was replaced or removed (a package upgraded during a shot), where the resolved
/// path would name the new program or nothing.
inline constexpr const char* kThisProgram = "/proc/self/exe";

struct PlateFile; // the header and native channel data, for rewriting channels bit for bit

struct Plate {
    std::string path;
    int width = 0, height = 0;                                           ///< data window size
    int originX = 0, originY = 0;                                        ///< data window origin
    int displayX = 0, displayY = 0, displayWidth = 0, displayHeight = 0; ///< display window
    /// The data window's top-left corner in display-window pixels: a display-window position less
    /// this is the same point in the data window's pixels.
    int dataOffsetX() const { return originX - displayX; }
    int dataOffsetY() const { return originY - displayY; }
    std::vector<std::string> channels;
    int r = -1, g = -1, b = -1, a = -1; ///< channel indices (g, b = r for a one-channel luminance plate)
    std::vector<float> pixels;          ///< every channel as float, interleaved, data window rows
    int subimages = 1;                  ///< parts in the file (only the first is used)
    std::vector<std::string> notes;     ///< what the reader decided (converted formats, ignored parts)
    std::shared_ptr<const PlateFile> file;

    std::size_t pixelCount() const { return static_cast<std::size_t>(width) * height; }
    float value(std::size_t pixel, int channel) const {
        return pixels[pixel * channels.size() + static_cast<std::size_t>(channel)];
    }
    /// R, G, B of the data window, interleaved.
    std::vector<float> rgb() const;
};

/// Reads the first part of an image. Throws ff::Error (Input) with the file name for anything that
/// is not a usable plate: unreadable, corrupt, too large (say which limit and how to raise it), deep,
/// no colour channels, or more than half of its pixels negative, NaN or infinite; ff::Error (Runtime)
/// when the checker was stopped by the wall-clock bound without having spent its CPU time.
Plate readPlate(const std::string& path, const PlateLimits& limits = {});

/// A plate from pixels in memory (`channels` interleaved, rows top to bottom; data window = display
/// window at 0, 0), its R, G, B (or Y) and A found and its values checked as readPlate does; `name`
/// stands for the file in messages.
Plate plateFromPixels(const std::string& name, int width, int height, std::vector<std::string> channels,
                      std::vector<float> pixels);

/// The checks every plate passes, however it is made (ff::Error, Input, naming `path`): its R, G, B
/// (or a luminance Y: a note) and A found among the channel names; no majority of negative, NaN or
/// infinite pixels (that is not image data).
void findChannels(const std::string& path, Plate& p);
void checkValues(const std::string& path, const Plate& p);

/// What the checker process runs: reads the file in full under a memory limit; exit status 0 when it
/// is a usable plate, else 3 with the reason on stderr (a crash or a hang is the caller's to see).
/// Once the header has passed the checks it writes `header BYTES` (the pixels as float) and a newline
/// to stdout, from which the guard sets its deadline for the pixels.
int checkPlate(const std::string& path, const PlateLimits& limits);

/// A layer simulate adds to the plate: channels name.R, name.G, name.B (float, or half) from `rgb`,
/// R, G, B interleaved over the data window.
struct Layer {
    std::string name;
    const std::vector<float>* rgb = nullptr;
};

/// Throws ff::Error (Input, naming the plate) when the plate already holds a channel one of the
/// layers `names` would add (name.R, .G, .B: a plate written by simulate): EXR channel names are
/// unique. writeSimulatedExr checks it; simulate checks it as soon as the plate is read.
void checkLayersFit(const Plate& plate, const std::vector<std::string>& names);

/// Writes an EXR (zip, scanlines) holding every channel of the plate unchanged — names, order, data
/// and display windows, metadata; channels stored as half, float or uint32 keep their bits, other
/// formats (8/16-bit integers) are written as float of the values read — followed by the layers'
/// channels in order (checkLayersFit first), as float or, with `half`, as half (16-bit float:
/// values beyond its largest, +-65504, are written as that, not as infinity). Atomic. Returns the
/// number of layer values that half saturated (0 for float); a NaN or infinity stays what it is.
std::size_t writeSimulatedExr(const std::string& path, const Plate& plate, const std::vector<Layer>& layers,
                              const Metadata& metadata, bool half = false);

} // namespace ff::image
