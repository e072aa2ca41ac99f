#include "export/godot_project.h"

#include "ghosts/table_json.h"

#include <string_view>

namespace ff::exporting {

namespace godot {
std::string_view embedded(std::string_view name); // src/export/godot/, generated (cmake/FFEmbed.cmake)
}

std::vector<std::pair<std::string, std::string>> godotProject(const ghosts::GhostTable& table) {
    auto file = [](const char* name) { return std::string(godot::embedded(name)); };
    return {{"project.godot", file("project.godot")},
            {"flare_frame.tscn", file("flare_frame.tscn")},
            {"flare_frame.gd", file("flare_frame.gd")},
            {"addons/fourierflare/lens_flare.gd", file("lens_flare.gd")},
            {"addons/fourierflare/lens_flare.shader", file("lens_flare.shader")},
            {"addons/fourierflare/ghost_table.json", ghosts::tableToJson(table, true)},
            {kGodotMarker, "A Godot 3 project written by fourierflare export --format godot for " + table.lensName +
                               " (" + table.lensHash + "); a later export may replace this folder.\n"}};
}

} // namespace ff::exporting
