#include "image/plate.h"

#include "core/error.h"
#include "image/atomic_write.h"

#include <OpenEXR/ImfRgbaFile.h>
#include <OpenImageIO/imageio.h>

#include <Imath/half.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace ff::image {

struct PlateFile {
    OIIO::ImageSpec spec;              ///< the first part's header as read
    std::vector<unsigned char> native; ///< its pixels in their native per-channel formats
};

namespace {

[[noreturn]] void bad(const std::string& path, const std::string& what) {
    throw Error(ErrorKind::Input, SourceLocation{path}, what);
}

std::string firstLine(std::string s) {
    if (const auto n = s.find('\n'); n != std::string::npos) s.resize(n);
    return s.empty() ? "unknown error" : s;
}

// Header checks, before any pixel is allocated.
void checkSpec(const std::string& path, const OIIO::ImageSpec& s, const PlateLimits& limits) {
    if (s.deep) bad(path, "deep images are not supported as plates");
    if (s.width <= 0 || s.height <= 0 || s.depth != 1)
        bad(path, "the image has no usable 2D data window (" + std::to_string(s.width) + "x" +
                      std::to_string(s.height) + ")");
    const std::uint64_t pixels = static_cast<std::uint64_t>(s.width) * static_cast<std::uint64_t>(s.height);
    if (pixels > limits.maxPixels)
        bad(path, "the image is " + std::to_string(s.width) + "x" + std::to_string(s.height) + " = " +
                      std::to_string(pixels) + " pixels, above the limit of " + std::to_string(limits.maxPixels) +
                      " (--max-pixels raises it)");
    if (s.nchannels < 1 || s.nchannels > limits.maxChannels)
        bad(path, "the image has " + std::to_string(s.nchannels) + " channels (1 to " +
                      std::to_string(limits.maxChannels) + " are supported)");
    if (limits.onHeader) limits.onHeader(pixels * static_cast<std::uint64_t>(s.nchannels) * sizeof(float));
}

// The data and display windows of a header.
void takeWindows(const OIIO::ImageSpec& spec, Plate& p) {
    p.width = spec.width;
    p.height = spec.height;
    p.originX = spec.x;
    p.originY = spec.y;
    p.displayX = spec.full_x;
    p.displayY = spec.full_y;
    p.displayWidth = spec.full_width > 0 ? spec.full_width : spec.width;
    p.displayHeight = spec.full_height > 0 ? spec.full_height : spec.height;
}

// An OpenEXR file whose channels are the luminance/chroma set (Y, RY, BY, the chroma subsampled),
// which OpenImageIO cannot read, read as R, G, B (A where it has one) through OpenEXR's
// RgbaInputFile: chroma reconstructed and converted with the file's chromaticities. The output then
// carries R, G, B (A) as half floats in place of Y, RY, BY. Empty when the file is not such an EXR.
std::optional<Plate> readLuminanceChroma(const std::string& path, const PlateLimits& limits, bool keepNative) {
    {
        std::FILE* f = std::fopen(path.c_str(), "rb");
        if (!f) return std::nullopt;
        unsigned char magic[4] = {};
        const std::size_t got = std::fread(magic, 1, 4, f);
        std::fclose(f);
        if (got != 4 || magic[0] != 0x76 || magic[1] != 0x2f || magic[2] != 0x31 || magic[3] != 0x01)
            return std::nullopt;
    }
    Plate p;
    p.path = path;
    std::vector<Imf::Rgba> px;
    std::unique_ptr<Imf::RgbaInputFile> file;
    try {
        file = std::make_unique<Imf::RgbaInputFile>(path.c_str());
    } catch (const std::exception&) {
        return std::nullopt; // not a readable EXR header: OpenImageIO's message says why
    }
    try {
        Imf::RgbaInputFile& f = *file;
        if (!(f.channels() & Imf::WRITE_C)) return std::nullopt;
        const Imath::Box2i dw = f.dataWindow(), disp = f.displayWindow();
        const long w = static_cast<long>(dw.max.x) - dw.min.x + 1, h = static_cast<long>(dw.max.y) - dw.min.y + 1;
        const int channels = (f.channels() & Imf::WRITE_A) ? 4 : 3;
        OIIO::ImageSpec spec(static_cast<int>(std::clamp(w, 0L, 1L << 30)),
                             static_cast<int>(std::clamp(h, 0L, 1L << 30)), channels, OIIO::TypeDesc::HALF);
        checkSpec(path, spec, limits); // before any pixel is allocated
        spec.x = dw.min.x;
        spec.y = dw.min.y;
        spec.full_x = disp.min.x;
        spec.full_y = disp.min.y;
        spec.full_width = static_cast<int>(std::clamp(static_cast<long>(disp.max.x) - disp.min.x + 1, 1L, 1L << 30));
        spec.full_height = static_cast<int>(std::clamp(static_cast<long>(disp.max.y) - disp.min.y + 1, 1L, 1L << 30));
        spec.channelnames = {"R", "G", "B"};
        if (channels == 4) spec.channelnames.emplace_back("A");
        px.resize(static_cast<std::size_t>(w * h));
        f.setFrameBuffer(px.data() - dw.min.x - static_cast<long>(dw.min.y) * w, 1, static_cast<std::size_t>(w));
        f.readPixels(dw.min.y, dw.max.y);

        takeWindows(spec, p);
        p.channels = spec.channelnames;
        p.notes.push_back("a luminance/chroma plate (Y, RY, BY): read as RGB through OpenEXR's RGBA interface; the "
                          "output carries R, G, B" +
                          std::string(channels == 4 ? ", A" : "") + " in their place");
        p.pixels.resize(px.size() * static_cast<std::size_t>(channels));
        std::vector<half> native(p.pixels.size());
        for (std::size_t i = 0; i < px.size(); ++i) {
            const half v[4] = {px[i].r, px[i].g, px[i].b, px[i].a};
            for (std::size_t c = 0; c < static_cast<std::size_t>(channels); ++c) {
                native[i * channels + c] = v[c];
                p.pixels[i * channels + c] = static_cast<float>(v[c]);
            }
        }
        if (keepNative) {
            auto kept = std::make_shared<PlateFile>();
            kept->spec = spec;
            kept->native.resize(native.size() * sizeof(half));
            std::memcpy(kept->native.data(), native.data(), kept->native.size());
            p.file = std::move(kept);
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        bad(path, "cannot read the luminance/chroma image: " + firstLine(e.what()));
    }
    findChannels(path, p);
    checkValues(path, p);
    return p;
}

// Opens, checks and reads the first part. `keepNative` also reads the native channel data.
Plate readDirect(const std::string& path, const PlateLimits& limits, bool keepNative) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        const std::string error = firstLine(OIIO::geterror());
        if (std::optional<Plate> yc = readLuminanceChroma(path, limits, keepNative)) return std::move(*yc);
        bad(path, "cannot read the image: " + error);
    }
    Plate p;
    p.path = path;
    const OIIO::ImageSpec spec = in->spec();
    checkSpec(path, spec, limits);
    takeWindows(spec, p);
    p.channels = spec.channelnames;
    p.subimages = spec.get_int_attribute("oiio:subimages", 1);
    if (p.subimages > 1)
        p.notes.push_back("the file has " + std::to_string(p.subimages) + " parts; only the first is used");
    findChannels(path, p);
    const int n = spec.nchannels;
    p.pixels.resize(p.pixelCount() * static_cast<std::size_t>(n));
    if (!in->read_image(0, 0, 0, n, OIIO::TypeDesc::FLOAT, p.pixels.data()))
        bad(path, "cannot read the pixels: " + firstLine(in->geterror()));
    checkValues(path, p);
    if (keepNative) {
        auto file = std::make_shared<PlateFile>();
        file->spec = spec;
        file->native.resize(p.pixelCount() * spec.pixel_bytes(true));
        if (!in->read_image(0, 0, 0, n, OIIO::TypeDesc::UNKNOWN, file->native.data()))
            bad(path, "cannot read the pixels: " + firstLine(in->geterror()));
        p.file = std::move(file);
    }
    return p;
}

// The CPU time (user + system, all threads) process `pid` has spent so far, in seconds; -1 when it
// cannot be read (the process has gone).
double cpuSecondsOf(pid_t pid) {
    char name[64];
    std::snprintf(name, sizeof name, "/proc/%d/stat", static_cast<int>(pid));
    std::FILE* f = std::fopen(name, "r");
    if (!f) return -1.0;
    char buf[1024];
    const std::size_t got = std::fread(buf, 1, sizeof buf - 1, f);
    std::fclose(f);
    buf[got] = '\0';
    // pid (comm) state ppid ... : utime and stime are fields 14 and 15, the 12th and 13th after the
    // command name, which may itself hold spaces and parentheses.
    const char* p = std::strrchr(buf, ')');
    unsigned long long utime = 0, stime = 0;
    if (!p || std::sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &utime, &stime) != 2)
        return -1.0;
    static const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
    return static_cast<double>(utime + stime) / tick;
}

// Seconds (or a factor) to three significant digits: 3, 0.15, 60, 3.04.
std::string secondsText(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", s);
    return text;
}

// Runs the checker on the file under the bounds of PlateLimits; throws what went wrong there. Its
// stderr (the reason it gives) and its stdout (the `header BYTES` line) come through pipes; its CPU
// time is read from /proc every 50 ms.
void guardedRead(const std::string& path, const PlateLimits& limits) {
    int err[2], out[2];
    if (pipe(err) != 0) throwRuntimeError("cannot create a pipe to check '" + path + "'");
    if (pipe(out) != 0) {
        close(err[0]), close(err[1]);
        throwRuntimeError("cannot create a pipe to check '" + path + "'");
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    for (int fd : {err[0], out[0], err[1], out[1]}) posix_spawn_file_actions_addclose(&actions, fd);
    const std::string pixels = std::to_string(limits.maxPixels), channels = std::to_string(limits.maxChannels);
    std::vector<std::string> args = {limits.checker,   "plate-check", "--max-pixels", pixels,
                                     "--max-channels", channels,      "--",           path};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, limits.checker.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(err[1]), close(out[1]);
    if (spawned != 0) {
        close(err[0]), close(out[0]);
        throwRuntimeError("cannot run the plate checker '" + limits.checker + "': " + std::strerror(spawned));
    }
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    // The current stage's bounds: CPU time (the checker's total) and wall-clock time (since spawning).
    double cpuBound = limits.cpuSeconds, wallBound = limits.wallFactor * limits.cpuSeconds, cpu = 0.0;
    enum class Over { No, Cpu, Wall } over = Over::No;
    auto overBound = [&] {
        if (const double c = cpuSecondsOf(pid); c >= 0.0) cpu = c;
        return cpu > cpuBound ? Over::Cpu : elapsed() > wallBound ? Over::Wall : Over::No;
    };
    bool headerPassed = false;
    std::string message, report;
    pollfd fds[2] = {{err[0], POLLIN, 0}, {out[0], POLLIN, 0}};
    while (fds[0].fd >= 0 || fds[1].fd >= 0) { // until both pipes are closed: the checker has finished (or died)
        if ((over = overBound()) != Over::No) break;
        const int ready = poll(fds, 2, 50);
        if (ready < 0 && errno != EINTR) break;
        for (int i = 0; ready > 0 && i < 2; ++i) {
            if (fds[i].fd < 0 || fds[i].revents == 0) continue;
            char buf[512];
            const ssize_t got = read(fds[i].fd, buf, sizeof buf);
            if (got <= 0) {
                close(fds[i].fd);
                fds[i].fd = -1; // poll ignores negative descriptors
                continue;
            }
            std::string& text = i == 0 ? message : report;
            if (text.size() < 4096) text.append(buf, static_cast<std::size_t>(got));
        }
        unsigned long long bytes = 0;
        if (!headerPassed && report.find('\n') != std::string::npos &&
            std::sscanf(report.c_str(), "header %llu", &bytes) == 1) {
            headerPassed = true;
            const double stage = limits.cpuSeconds + static_cast<double>(bytes) / limits.floatBytesPerSecond;
            if (const double c = cpuSecondsOf(pid); c >= 0.0) cpu = c;
            cpuBound = cpu + stage;
            wallBound = elapsed() + limits.wallFactor * stage;
        }
    }
    for (const pollfd& p : fds)
        if (p.fd >= 0) close(p.fd);
    int status = 0;
    while (over == Over::No && waitpid(pid, &status, WNOHANG) == 0) {
        if ((over = overBound()) == Over::No) usleep(1000);
    }
    if (over != Over::No) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        const std::string stage = headerPassed ? "reading the image's pixels" : "reading the image's header";
        const std::string raise = "; FF_PLATE_CHECK_SECONDS raises the bound (now " + secondsText(limits.cpuSeconds) +
                                  " s of CPU time for the header, the wall-clock bound " +
                                  secondsText(limits.wallFactor) + " times that)";
        if (over == Over::Cpu)
            bad(path, stage + " spent " + secondsText(cpu) + " s of CPU time without finishing, more than its " +
                          secondsText(cpuBound) + " s: the image library is stuck in a loop (a corrupt file?)" + raise);
        // Out of wall-clock time with CPU time left: it waited (a lock in the library, a file system
        // that does not answer, or a machine far busier than any node should be). Not evidence of a
        // bad file, so not an input error (a farm may retry).
        throw Error(ErrorKind::Runtime, SourceLocation{path},
                    stage + " did not finish within " + secondsText(wallBound) + " s, having spent " +
                        secondsText(cpu) + " of its " + secondsText(cpuBound) +
                        " s of CPU time: it waited (for a file system that does not answer, a lock in the image " +
                        "library or a machine's cores)" + raise);
    }
    if (WIFSIGNALED(status))
        bad(path, "the image library crashed reading this file (signal " + std::to_string(WTERMSIG(status)) +
                      "): it is corrupt or hostile");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 3) bad(path, firstLine(message));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        bad(path, "the image library failed reading this file (exit status " +
                      std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + "): it is corrupt or hostile");
}

} // namespace

int checkPlate(const std::string& path, const PlateLimits& limits) {
#if !defined(__SANITIZE_ADDRESS__)
    // Pixels as float plus the library's own buffers: a header that lies about its sizes fails here
    // instead of exhausting the machine. Until the header has passed its checks, the process may grow
    // by kHeaderAddressSpace only: a header is small, and a damaged one declaring a gigabyte string
    // fails at once instead of spending seconds of CPU time filling it. (AddressSanitizer reserves far
    // more address space: no limit.)
    const rlim_t budget =
        static_cast<rlim_t>(limits.maxPixels) * static_cast<rlim_t>(limits.maxChannels) * 8u + (rlim_t(4) << 30);
    constexpr rlim_t kHeaderAddressSpace = rlim_t(1) << 30;
    rlim_t now = 0;
    if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
        unsigned long long pages = 0;
        if (std::fscanf(f, "%llu", &pages) == 1)
            now = static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE));
        std::fclose(f);
    }
    const rlimit rl{now > 0 ? std::min(budget, now + kHeaderAddressSpace) : budget, budget};
    setrlimit(RLIMIT_AS, &rl);
#endif
    PlateLimits reporting = limits;
    reporting.onHeader = [](std::uint64_t floatBytes) {
#if !defined(__SANITIZE_ADDRESS__)
        rlimit whole{};
        if (getrlimit(RLIMIT_AS, &whole) == 0) {
            whole.rlim_cur = whole.rlim_max; // the header has passed: the pixels get the whole budget
            setrlimit(RLIMIT_AS, &whole);
        }
#endif
        std::printf("header %llu\n", static_cast<unsigned long long>(floatBytes));
        std::fflush(stdout);
    };
    std::string message;
    try {
        readDirect(path, reporting, false);
        return 0;
    } catch (const Error& e) {
        message = e.message();
    } catch (const std::bad_alloc&) {
        message = "the image library ran out of memory reading it (a corrupt size in the file?)";
    } catch (const std::exception& e) {
        message = e.what();
    }
    std::fprintf(stderr, "%s\n", message.c_str());
    return 3;
}

double plateCheckSeconds() {
    const char* text = std::getenv("FF_PLATE_CHECK_SECONDS");
    if (!text || !*text) return kPlateCheckSeconds;
    char* end = nullptr;
    errno = 0;
    const double s = std::strtod(text, &end);
    if (errno != 0 || *end != '\0' || !(s >= 0.1 && s <= 86400.0))
        throw Error(ErrorKind::Usage, std::string("FF_PLATE_CHECK_SECONDS is '") + text +
                                          "': it must be a number of seconds from 0.1 to 86400");
    return s;
}

Plate readPlate(const std::string& path, const PlateLimits& limits) {
    if (!limits.checker.empty()) guardedRead(path, limits);
    return readDirect(path, limits, true);
}

void checkLayersFit(const Plate& plate, const std::vector<std::string>& names) {
    // A second channel of a name would be renamed by the EXR writer (channel7) and the plate's channel
    // lose its name, or be taken for the layer's.
    for (const std::string& name : names)
        for (const char* c : {".R", ".G", ".B"})
            if (std::find(plate.channels.begin(), plate.channels.end(), name + c) != plate.channels.end())
                bad(plate.path, "the plate already has a channel " + name + c + ", which the " + name +
                                    " layer would add (a plate written by simulate? remove that layer from it, or "
                                    "ask for other --layers)");
}

std::size_t writeSimulatedExr(const std::string& path, const Plate& plate, const std::vector<Layer>& layers,
                              const Metadata& metadata, bool half) {
    if (!plate.file) throwRuntimeError("writeSimulatedExr: the plate has no file");
    std::vector<std::string> names;
    for (const Layer& l : layers) {
        if (!l.rgb || l.rgb->size() != plate.pixelCount() * 3)
            throwRuntimeError("writeSimulatedExr: the layer " + l.name + " does not match the plate");
        names.push_back(l.name);
    }
    checkLayersFit(plate, names);
    const OIIO::ImageSpec& in = plate.file->spec;
    const int n = in.nchannels;
    // Input channel formats; those EXR cannot store are written as float.
    std::vector<OIIO::TypeDesc> inFormat(static_cast<std::size_t>(n)), outFormat(static_cast<std::size_t>(n));
    std::vector<std::size_t> inOffset(static_cast<std::size_t>(n));
    std::size_t offset = 0;
    for (int c = 0; c < n; ++c) {
        const OIIO::TypeDesc f = in.channelformats.empty() ? in.format : in.channelformats[static_cast<std::size_t>(c)];
        inFormat[static_cast<std::size_t>(c)] = f;
        inOffset[static_cast<std::size_t>(c)] = offset;
        offset += f.size();
        const bool exact = f == OIIO::TypeDesc::HALF || f == OIIO::TypeDesc::FLOAT || f == OIIO::TypeDesc::UINT32;
        outFormat[static_cast<std::size_t>(c)] = exact ? f : OIIO::TypeDesc(OIIO::TypeDesc::FLOAT);
    }
    const std::size_t inPixelBytes = offset;

    OIIO::ImageSpec out = in;
    out.tile_width = out.tile_height = out.tile_depth = 0;
    out.erase_attribute("oiio:subimages");
    out.erase_attribute("compression");
    out.attribute("compression", "zip");
    const OIIO::TypeDesc layerFormat = half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT;
    for (const Layer& l : layers)
        for (const char* c : {".R", ".G", ".B"}) {
            out.channelnames.emplace_back(l.name + c);
            outFormat.emplace_back(layerFormat);
        }
    out.nchannels = n + 3 * static_cast<int>(layers.size());
    out.channelformats = outFormat;
    out.format = OIIO::TypeDesc::FLOAT;
    for (const auto& [k, v] : metadata) out.attribute(k, v);

    std::size_t outPixelBytes = 0, saturated = 0;
    for (const auto& f : outFormat) outPixelBytes += f.size();
    std::vector<unsigned char> buffer(plate.pixelCount() * outPixelBytes);
    constexpr float kHalfMax = 65504.0f;
    for (std::size_t p = 0; p < plate.pixelCount(); ++p) {
        unsigned char* dst = &buffer[p * outPixelBytes];
        const unsigned char* src = &plate.file->native[p * inPixelBytes];
        for (int c = 0; c < n; ++c) {
            const std::size_t ci = static_cast<std::size_t>(c);
            if (outFormat[ci] == inFormat[ci])
                std::memcpy(dst, src + inOffset[ci], inFormat[ci].size());
            else {
                const float v = plate.value(p, c);
                std::memcpy(dst, &v, sizeof v);
            }
            dst += outFormat[ci].size();
        }
        for (const Layer& l : layers) {
            if (!half) {
                std::memcpy(dst, &(*l.rgb)[p * 3], 3 * sizeof(float));
                dst += 3 * sizeof(float);
                continue;
            }
            for (int c = 0; c < 3; ++c) {
                float v = (*l.rgb)[p * 3 + static_cast<std::size_t>(c)];
                if (std::isfinite(v) && std::abs(v) > kHalfMax) {
                    v = std::copysign(kHalfMax, v);
                    ++saturated;
                }
                const Imath::half h(v);
                std::memcpy(dst, &h, sizeof h);
                dst += sizeof h;
            }
        }
    }
    writeAtomic(path, out, OIIO::TypeDesc::UNKNOWN, buffer.data());
    return saturated;
}

} // namespace ff::image
