#include "cli/conventions.h"

#include "core/error.h"
#include "optics/lens_loader.h"

namespace ff::cli {

namespace {

// A lens file, or the name of an installed lens (optics::findLensFile), replaced by its path.
const CLI::Validator kLensFile(
    [](std::string& value) {
        try {
            value = optics::findLensFile(value).string();
            return std::string();
        } catch (const Error& e) {
            return std::string(e.what());
        }
    },
    "FILE|NAME");

} // namespace

void addLensArgument(CLI::App& cmd, std::string& lens, const std::string& help) {
    const std::string what = help + ", or an installed lens's name (double-gauss-50mm-f2)";
    CLI::Option* positional = cmd.add_option("lens", lens, what + "; or --lens")->transform(kLensFile);
    cmd.add_option("--lens", lens, what + "; or as the first argument")->transform(kLensFile)->excludes(positional);
}

void requireLens(const std::string& lens) {
    if (lens.empty()) throw Error(ErrorKind::Usage, "a lens is required: give it as the first argument or with --lens");
}

} // namespace ff::cli
