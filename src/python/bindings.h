#pragma once
// The Python module's parts, each registering its classes and functions (docs/python.md).

#include "ghosts/table_data.h"
#include "optics/lens.h"

#include <memory>
#include <pybind11/pybind11.h>

namespace ff::python {

void bindLens(pybind11::module_& m);     ///< Lens
void bindGhosts(pybind11::module_& m);   ///< ghost_report, GhostTable
void bindRender(pybind11::module_& m);   ///< render
void bindSimulate(pybind11::module_& m); ///< simulate
void bindCompare(pybind11::module_& m);  ///< compare

/// The lens's table from the cache or built, without the GIL; `progress` (None or a callable
/// (done, total)) is called as it goes and may stop it (Interruptible).
std::shared_ptr<ghosts::GhostTable> buildTable(const optics::Lens& lens, const ghosts::TableSettings& settings,
                                               bool useCache, const pybind11::object& progress);

} // namespace ff::python
