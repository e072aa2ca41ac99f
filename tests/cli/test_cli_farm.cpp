// What a render farm does to the tool (docs/farm.md): several processes building the same cache
// entries at once, a read-only cache folder, a full disk, processes killed mid-frame, and frames
// rerun with --skip-existing. No file is ever visible under its final name unless it is whole.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <map>
#include <random>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "cli_runner.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

const std::string kLens = std::string(FF_SOURCE_DIR) + "/lenses/cooke-triplet-50mm-f5.lens";
// A small table: the cold build (shaped table + PSF) takes a few seconds, so kills land in every stage.
const std::string kOptions = " --table-grid 16 --table-angles 9 --backend cpu --preview out.png";

void writePlate(const fs::path& path, int lightX, int lightY, int W = 96, int H = 64) {
    std::vector<float> rgb(static_cast<std::size_t>(W) * H * 3, 0.02f);
    for (int y = lightY; y < lightY + 2; ++y)
        for (int x = lightX; x < lightX + 2; ++x)
            for (int c = 0; c < 3; ++c) rgb[(static_cast<std::size_t>(y) * W + x) * 3 + c] = 900.0f;
    OIIO::ImageSpec spec(W, H, 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("DateTime", "");
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out && out->open(path.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()) &&
                out->close());
}

// `simulate` of plate.exr in `dir` (its working folder: every process writes out.exr there, so the
// command lines, and the files, are the same in every folder).
std::string simulateIn(const fs::path& dir, const fs::path& cache, const std::string& extra = "") {
    return "cd '" + dir.string() + "' && FF_CACHE_DIR='" + cache.string() + "' exec '" + FF_CLI_PATH +
           "' -q simulate --lens '" + kLens + "' --plate ../plate.exr -o out.exr" + kOptions + extra;
}

// Starts `command` under sh; returns its pid (the shell execs the tool, so it is the tool's pid).
pid_t spawn(const std::string& command, const fs::path& errFile) {
    const pid_t pid = fork();
    if (pid == 0) {
        const std::string full = command + " 2>'" + errFile.string() + "'";
        execl("/bin/sh", "sh", "-c", full.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    return pid;
}

int waitFor(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The files of a folder by name, with their bytes (no subfolders).
std::map<std::string, std::string> filesIn(const fs::path& dir) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file()) out[e.path().filename().string()] = ff::test::readFile(e.path());
    return out;
}

bool isTemporary(const std::string& name) {
    return name.find(".tmp") != std::string::npos;
}

// The reference: one process, a cold cache of its own.
struct Reference {
    std::map<std::string, std::string> outputs, cache;
};

Reference referenceRun(const ff::test::TempDir& root) {
    fs::create_directories(root / "ref");
    const pid_t pid = spawn(simulateIn(root / "ref", root / "ref-cache"), root / "ref.err");
    EXPECT_EQ(waitFor(pid), 0) << ff::test::readFile(root / "ref.err");
    Reference r{filesIn(root / "ref"), filesIn(root / "ref-cache")};
    EXPECT_EQ(r.outputs.size(), 2u);
    EXPECT_EQ(r.cache.size(), 2u); // one shaped table, one PSF
    return r;
}

// One busy process per core for as long as it lives: the load of a node running other work. The
// loops die with the test's process too (a killed test must not leave them spinning).
class BusyMachine {
  public:
    BusyMachine() {
        const pid_t parent = getpid();
        for (unsigned i = 0; i < std::max(1u, std::thread::hardware_concurrency()); ++i) {
            const pid_t pid = fork();
            if (pid == 0) {
                if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent) _exit(0);
                execl("/bin/sh", "sh", "-c", "while :; do :; done", static_cast<char*>(nullptr));
                _exit(127);
            }
            pids_.push_back(pid);
        }
    }
    ~BusyMachine() {
        for (pid_t pid : pids_) kill(pid, SIGKILL);
        for (pid_t pid : pids_) waitpid(pid, nullptr, 0);
    }
    BusyMachine(const BusyMachine&) = delete;
    BusyMachine& operator=(const BusyMachine&) = delete;

  private:
    std::vector<pid_t> pids_;
};

// n processes started together, 0-300 ms apart (some start while others are writing the entries
// they read), on a machine kept busy beside them, with a cold cache of their own: each must read
// the plate, and they leave the outputs and the cache entries of a lone process.
void buildTogether(const ff::test::TempDir& root, const Reference& ref, int n, std::mt19937& rng) {
    SCOPED_TRACE("processes: " + std::to_string(n));
    const BusyMachine busy;
    const fs::path cache = root / ("cache-" + std::to_string(n));
    std::vector<pid_t> pids;
    for (int i = 0; i < n; ++i) {
        const fs::path dir = root / ("n" + std::to_string(n) + "-" + std::to_string(i));
        fs::create_directories(dir);
        pids.push_back(spawn(simulateIn(dir, cache), dir.string() + ".err"));
        std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(0, 300)(rng)));
    }
    for (int i = 0; i < n; ++i) {
        const fs::path dir = root / ("n" + std::to_string(n) + "-" + std::to_string(i));
        const std::string err = dir.string() + ".err";
        EXPECT_EQ(waitFor(pids[static_cast<std::size_t>(i)]), 0) << ff::test::readFile(err);
        EXPECT_EQ(ff::test::readFile(err), "") << "no note of an unreadable or unstored entry";
        const auto outputs = filesIn(dir);
        EXPECT_TRUE(outputs == ref.outputs) << "process " << i << ": outputs differ from a lone process's";
        fs::remove_all(dir);
    }
    const auto entries = filesIn(cache);
    EXPECT_TRUE(entries == ref.cache) << "the cache holds " << entries.size() << " files, not the 2 entries";
    for (const auto& [name, bytes] : entries) EXPECT_FALSE(isTemporary(name)) << name;
    fs::remove_all(cache);
}

} // namespace

TEST(CliFarm, ProcessesBuildingTheSameCacheEntriesLeaveOneValidEntryAndTheSameOutputs) {
    ff::test::TempDir root;
    writePlate(root / "plate.exr", 60, 20);
    const Reference ref = referenceRun(root);
    std::mt19937 rng(46);
    for (int n : {2, 4, 8}) buildTogether(root, ref, n, rng);
}

TEST(CliFarm, SixteenProcessesOnABusyMachineEachReadTheValidPlate) {
    // 16 processes and a busy loop per core: 9 runnable processes a core on 2 cores, where a
    // wall-clock bound of 3 s on the plate's check refused the valid plate in every run.
    ff::test::TempDir root;
    writePlate(root / "plate.exr", 60, 20);
    const Reference ref = referenceRun(root);
    std::mt19937 rng(58);
    buildTogether(root, ref, 16, rng);
}

TEST(CliFarm, AReadOnlyCacheFolderWorksWithANote) {
    ff::test::TempDir root;
    writePlate(root / "plate.exr", 30, 40);
    const Reference ref = referenceRun(root);
    fs::create_directories(root / "ro-cache");
    fs::create_directories(root / "run");
    fs::permissions(root.path(), fs::perms::all);
    fs::permissions(root / "run", fs::perms::all);
    fs::permissions(root / "ro-cache", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                           fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
    // Root writes anywhere: the tool then runs as nobody, for whom the folder is read-only.
    const std::string as = geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "";
    std::string command = simulateIn(root / "run", root / "ro-cache");
    command.replace(command.find("exec '"), 6, "exec " + as + "'");
    command.replace(command.find(" -q "), 4, " ");
    const pid_t pid = spawn(command, root / "run.err");
    const std::string err = (waitFor(pid), ff::test::readFile(root / "run.err"));
    ASSERT_TRUE(fs::exists(root / "run" / "out.exr")) << err;
    EXPECT_TRUE(filesIn(root / "run") == ref.outputs) << err;
    EXPECT_TRUE(filesIn(root / "ro-cache").empty());
    EXPECT_NE(err.find("note: the cache folder " + (root / "ro-cache").string() + " is not writable"),
              std::string::npos)
        << err;
    EXPECT_EQ(err.find("warning"), std::string::npos) << err;
}

TEST(CliFarm, AFullDiskFailsCleanly) {
    ff::test::TempDir root;
    writePlate(root / "plate.exr", 30, 40);
    const Reference ref = referenceRun(root);
    // A file-size limit of 48 KiB: the PSF entry (~45 KB) fits, the shaped table (~MBs) and the EXR
    // (~60 KB) do not. As a full disk, every write past it fails (EFBIG).
    fs::create_directories(root / "run");
    const std::string command = "ulimit -f 48 && " + simulateIn(root / "run", root / "cache");
    const pid_t pid = spawn(command, root / "run.err");
    const int code = waitFor(pid);
    const std::string err = ff::test::readFile(root / "run.err");
    EXPECT_EQ(code, 1) << err;
    EXPECT_NE(err.find("error: cannot write 'out.exr'"), std::string::npos) << err;
    EXPECT_NE(err.find("File too large"), std::string::npos) << err;
    EXPECT_TRUE(filesIn(root / "run").empty()) << "no output, no temporary file";
    // The cache holds only whole entries (here the PSF, identical to a lone run's), no temporaries.
    for (const auto& [name, bytes] : filesIn(root / "cache")) {
        EXPECT_FALSE(isTemporary(name)) << name;
        ASSERT_TRUE(ref.cache.count(name)) << name;
        EXPECT_TRUE(bytes == ref.cache.at(name)) << name << " is not the whole entry";
    }
}

TEST(CliFarm, KilledMidFrameNeverLeavesAPartialFileUnderItsFinalName) {
    ff::test::TempDir root;
    // A large plate: writing its EXR and PNG takes a good share of the run, so kills land there too.
    writePlate(root / "plate.exr", 900, 200, 1600, 800);
    auto seconds = [](auto since) {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
    };
    auto t0 = std::chrono::steady_clock::now();
    const Reference ref = referenceRun(root);
    double cold = seconds(t0);
    fs::create_directories(root / "warm");
    t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(waitFor(spawn(simulateIn(root / "warm", root / "ref-cache"), root / "warm.err")), 0);
    double warm = seconds(t0);
    // 20 kills that land mid-frame, at uniform moments of a run: cold runs (their kills land in the
    // table's build, the cache's writes, the render and the image writes) alternate with runs on
    // the warm cache. A run that ends before its kill is not counted, and the next draw of that
    // kind is made over a shorter span.
    std::mt19937 rng(47);
    int killed = 0, partial = 0, attempt = 0;
    for (; killed < 20 && attempt < 80; ++attempt) {
        SCOPED_TRACE("attempt " + std::to_string(attempt));
        const fs::path dir = root / ("k" + std::to_string(attempt)), cache = root / ("kc" + std::to_string(attempt));
        fs::create_directories(dir);
        const bool onWarm = attempt % 2 == 1;
        const fs::path useCache = onWarm ? root / "ref-cache" : cache;
        double& span = onWarm ? warm : cold;
        const double at = std::uniform_real_distribution<double>(0.0, 0.9 * span)(rng);
        const pid_t pid = spawn(simulateIn(dir, useCache), dir.string() + ".err");
        std::this_thread::sleep_for(std::chrono::duration<double>(at));
        const bool landed = kill(pid, SIGKILL) == 0 && waitFor(pid) == 128 + SIGKILL;
        killed += landed;
        if (!landed) span *= 0.8;
        for (const auto& [name, bytes] : filesIn(dir)) {
            if (isTemporary(name)) continue;
            ASSERT_TRUE(ref.outputs.count(name)) << name;
            partial += bytes != ref.outputs.at(name);
        }
        if (!onWarm && fs::exists(cache))
            for (const auto& [name, bytes] : filesIn(cache)) {
                if (isTemporary(name)) continue;
                ASSERT_TRUE(ref.cache.count(name)) << name;
                partial += bytes != ref.cache.at(name);
            }
        // The frame rerun over what the kill left: the same files.
        ASSERT_EQ(waitFor(spawn(simulateIn(dir, useCache, " --skip-existing"), dir.string() + ".err")), 0)
            << ff::test::readFile(dir.string() + ".err");
        auto outputs = filesIn(dir);
        std::erase_if(outputs, [](const auto& f) { return isTemporary(f.first); });
        EXPECT_TRUE(outputs == ref.outputs);
    }
    EXPECT_EQ(killed, 20) << "in " << attempt << " attempts";
    EXPECT_EQ(partial, 0);
    std::printf("[ %d kills mid-frame in %d runs (cold %.1f s, warm %.1f s at the end); partial files under a "
                "final name: %d ]\n",
                killed, attempt, cold, warm, partial);
}

TEST(CliFarm, SkipExistingRendersOnlyTheMissingFramesAndTheirBytesDoNotDependOnTheSplit) {
    ff::test::TempDir root;
    fs::create_directories(root / "plates");
    for (int f = 1; f <= 6; ++f)
        writePlate(root / "plates" / ("plate." + std::to_string(1000 + f) + ".exr"), 10 + 12 * f, 30);
    const std::string base = std::string("FF_CACHE_DIR='") + (root / "cache").string() + "' ";
    const std::string sim = "simulate --lens '" + kLens + "' --plate '" + (root / "plates").string() +
                            "/plate.%04d.exr' -o '" + (root / "out").string() + "/f.%04d.exr' --table-grid 16 " +
                            "--table-angles 9 --backend cpu --frames ";
    fs::create_directories(root / "out");
    ASSERT_EQ(ff::test::run(sim + "1001-1006", base).code, 0);
    const auto whole = filesIn(root / "out");
    ASSERT_EQ(whole.size(), 6u);
    fs::remove_all(root / "out");
    fs::create_directories(root / "out");
    // The shot in three ranges, then two frames lost and the whole range rerun with --skip-existing.
    for (const char* range : {"1001-1002", "1003-1005", "1006-1006"})
        ASSERT_EQ(ff::test::run("--threads 1 " + sim + range + " --skip-existing", base).code, 0);
    EXPECT_TRUE(filesIn(root / "out") == whole) << "frames depend on the range that rendered them";
    fs::remove(root / "out" / "f.1002.exr");
    fs::remove(root / "out" / "f.1005.exr");
    const auto r = ff::test::run(sim + "1001-1006 --skip-existing", base);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("--skip-existing: 4 of 6 frames already written, skipped"), std::string::npos) << r.err;
    EXPECT_TRUE(filesIn(root / "out") == whole);
}
