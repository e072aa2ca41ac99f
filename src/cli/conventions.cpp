#include "cli/conventions.h"

#include "core/error.h"

namespace ff::cli {

void addLensArgument(CLI::App& cmd, std::string& lens, const std::string& help) {
    CLI::Option* positional = cmd.add_option("lens", lens, help + "; or --lens")->check(CLI::ExistingFile);
    cmd.add_option("--lens", lens, help + "; or as the first argument")->check(CLI::ExistingFile)->excludes(positional);
}

void requireLens(const std::string& lens) {
    if (lens.empty()) throw Error(ErrorKind::Usage, "a lens is required: give it as the first argument or with --lens");
}

} // namespace ff::cli
