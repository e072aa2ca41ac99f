#pragma once
// The Python module's parts, each registering its classes and functions (docs/python.md).

#include "ghosts/table_data.h"
#include "optics/lens.h"

#include <memory>
#include <pybind11/pybind11.h>
#include <string>

namespace ff::python {

void bindLens(pybind11::module_& m);     ///< Lens
void bindGhosts(pybind11::module_& m);   ///< ghost_report, GhostTable
void bindRender(pybind11::module_& m);   ///< render
void bindSimulate(pybind11::module_& m); ///< simulate
void bindCompare(pybind11::module_& m);  ///< compare

/// The ghost table's options, named as the CLI's (--table-grid, --sampling, --sensor, --coating,
/// --max-angle, --table-angles, --tolerance), checked against the same ranges (ff::Error, Usage).
struct TableArgs {
    int grid = 32;
    std::string sampling = "reaim", sensor = "file", coating = "file";
    double maxAngle = 0.0;
    int angles = 64;
    double tolerance = 0.005;
    ghosts::TableSettings settings() const;
};

/// The lens's table from the cache or built, without the GIL; `progress` (None or a callable
/// (done, total)) is called as it goes and may stop it (Interruptible).
std::shared_ptr<ghosts::GhostTable> buildTable(const optics::Lens& lens, const TableArgs& args, bool useCache,
                                               const pybind11::object& progress);

} // namespace ff::python
