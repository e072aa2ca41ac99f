#pragma once
// Each subcommand registers itself on the application; its callback parses nothing further, calls
// the libraries and prints. Errors propagate as ff::Error and are mapped to exit codes in main.

#include "cli/console.h"

namespace CLI {
class App;
}

namespace ff::cli {

void addLensCommand(CLI::App& app, GlobalOptions& global);
void addGhostsCommand(CLI::App& app, GlobalOptions& global);
void addRenderCommand(CLI::App& app, GlobalOptions& global);
void addTableCommand(CLI::App& app, GlobalOptions& global);
void addExportCommand(CLI::App& app, GlobalOptions& global);
void addCompareCommand(CLI::App& app, GlobalOptions& global);
void addSimulateCommand(CLI::App& app, GlobalOptions& global);
void addPlateCheckCommand(CLI::App& app);

} // namespace ff::cli
