#pragma once
// Runs the fourierflare executable from the repository root, capturing stdout, stderr and the exit code.

#include <cstdlib>
#include <string>
#include <sys/wait.h>

#include "test_support.h"

namespace ff::test {

struct RunResult {
    int code = -1;
    std::string out, err;
};

/// env: optional "NAME=value ..." assignments for the command's environment.
inline RunResult run(const std::string& args, const std::string& env = "") {
    TempDir dir;
    const std::string cmd = std::string("cd '") + FF_SOURCE_DIR + "' && " + env + " '" + FF_CLI_PATH + "' " + args +
                            " >'" + (dir / "out").string() + "' 2>'" + (dir / "err").string() + "'";
    const int status = std::system(cmd.c_str());
    RunResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readFile(dir / "out");
    r.err = readFile(dir / "err");
    return r;
}

} // namespace ff::test
