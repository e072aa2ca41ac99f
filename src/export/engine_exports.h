#pragma once
// Ghost tables in the forms game engines import without code (docs/exports.md has worked examples):
//  - CSV: one row per ghost, first column Name (an Unreal DataTable row name);
//  - Unity SRP: a LensFlareDataSRP .asset (YAML) with one element per ghost;
//  - Unreal: the built-in lens flare's LensFlareTints[8] for the 8 strongest ghosts.
// The canonical JSON is ghosts/table_json.h.

#include "export/ghost_summary.h"

#include <string>

namespace ff::exporting {

std::string toCsv(const ghosts::GhostTable& table, double fieldAngleDeg, std::size_t top);
std::string toUnityAsset(const ghosts::GhostTable& table, double fieldAngleDeg, std::size_t top,
                         const std::string& assetName);
std::string toUnrealPreset(const ghosts::GhostTable& table, double fieldAngleDeg);

} // namespace ff::exporting
