// fourierflare: command-line entry point. Parses, dispatches to one subcommand, and maps errors to
// exit codes (docs/cli.md): 0 ok, 1 runtime failure, 2 usage or input error.

#include "cli/commands.h"
#include "cli/console.h"
#include "core/error.h"
#include "ff/version.h"
#include "image/header_time.h"
#include "image/image_output.h"

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <thread>

int main(int argc, char** argv) {
    using namespace ff::cli;
    // Under a file-size limit (ulimit -f) a write that passes it fails with EFBIG, reported as an
    // error, instead of the signal killing the process with its temporary files left behind.
    std::signal(SIGXFSZ, SIG_IGN);
    CLI::App app{"FourierFlare: physically based lens flares from real lens prescriptions.", "fourierflare"};
    app.set_version_flag("--version", std::string("fourierflare ") + ff::kVersion);
    app.require_subcommand(1);
    app.option_defaults()->always_capture_default();
    app.footer("Exit codes: 0 ok, 1 runtime failure, 2 usage or input error.\n"
               "Example: fourierflare simulate --lens lenses/double-gauss-50mm-f2.lens --plate data/night-street.exr "
               "-o out/night-street.exr --preview out/night-street.png");
    GlobalOptions global;
    // The command line as written into output headers, without the options that change no output
    // (--threads, -q, -v): the same command on 1 or 2 threads, quiet or not, writes the same bytes.
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--threads" && i + 1 < argc) {
            ++i;
            continue;
        }
        if (a.rfind("--threads=", 0) == 0 || a == "-q" || a == "--quiet" || a == "-v" || a == "--verbose" ||
            a == "-qv" || a == "-vq")
            continue;
        global.commandLine += (global.commandLine.empty() ? "" : " ") + a;
        global.arguments.push_back(a);
    }
    app.add_flag("-q,--quiet", global.quiet, "Do not print notes (warnings and errors are always printed)");
    int threads = 0;
    app.add_option("--threads", threads, "Worker threads (default: all cores); results do not depend on it")
        ->check(CLI::Range(1, 1024));
    app.add_flag("-v,--verbose", global.verbose,
                 "Print every choice made on the way (Fourier period, terms, routes; stage times)");
    addLensCommand(app, global);
    addGhostsCommand(app, global);
    addRenderCommand(app, global);
    addTableCommand(app, global);
    addExportCommand(app, global);
    addCompareCommand(app, global);
    addSimulateCommand(app, global);
    addPlateCheckCommand(app);

    std::unique_ptr<tbb::global_control> threadLimit;
    app.parse_complete_callback([&] {
        ff::image::headerDateTime(); // a malformed SOURCE_DATE_EPOCH is refused before any work
        // EXR (de)compression on as many threads as the rest of the work.
        ff::image::setExrThreads(threads > 0 ? threads
                                             : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
        if (threads > 0)
            threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                                static_cast<std::size_t>(threads));
    });
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        printError(e.what());
        std::fprintf(stderr, "Run 'fourierflare --help' (or '<command> --help') for usage.\n");
        return 2;
    } catch (const ff::Error& e) {
        printError(e.what());
        return ff::exitCodeFor(e.kind());
    } catch (const std::exception& e) {
        printError(e.what());
        return 1;
    }
    return 0;
}
