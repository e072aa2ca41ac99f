#pragma once
// A ghost table as a Godot 3 project (docs/exports.md): the add-on a game takes
// (addons/fourierflare/: the table as the canonical JSON, a ColorRect script that instances the
// ghosts of lights at screen positions as ghosts::instantiate does, and a canvas shader that
// draws them as fourier::drawDirect does, tonemapped as the CLI's preview), and a minimal project
// around it whose main scene renders one frame from the command line:
//   godot3 --path DIR -- --light X,Y --size WxH --exposure EV --output FRAME.png
// The scripts and the shader are the files of src/export/godot/, built into the binary.

#include "ghosts/table_data.h"

#include <string>
#include <utility>
#include <vector>

namespace ff::exporting {

/// The file that marks a folder as such a project (an export may replace it).
inline constexpr const char* kGodotMarker = ".fourierflare-godot";

/// The project's files: (path relative to the project folder, content), the folders implied.
std::vector<std::pair<std::string, std::string>> godotProject(const ghosts::GhostTable& table);

} // namespace ff::exporting
