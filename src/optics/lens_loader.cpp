#include "optics/lens_loader.h"

#include "core/error.h"
#include "core/file_io.h"
#include "core/install_paths.h"
#include "core/text.h"
#include "optics/dat_importer.h"
#include "optics/lens_parser.h"
#include "optics/zmx_importer.h"
#include "optics/zoom.h"

namespace ff::optics {

Lens parseLensBytes(std::string_view bytes, const std::string& format, const std::string& fileName,
                    Reporter* reporter) {
    Lens lens;
    if (format == "lens")
        lens = parseLensText(bytes, fileName, reporter);
    else if (format == "zmx")
        lens = importZmx(bytes, fileName, reporter);
    else if (format == "dat")
        lens = importDat(bytes, fileName, reporter);
    else
        throw Error(ErrorKind::Usage,
                    "unknown lens format " + text::quoted(format) + "; valid formats: lens, zmx, dat");
    lens.format = format;
    lens.contentHash = hashHex(bytes);
    return lens;
}

Lens loadLens(const std::filesystem::path& path, Reporter* reporter) {
    const std::string ext = text::toLower(path.extension().string());
    std::string format;
    if (ext == ".lens")
        format = "lens";
    else if (ext == ".zmx")
        format = "zmx";
    else if (ext == ".dat")
        format = "dat";
    else
        throwInputError({path.string()}, "unknown lens file extension " +
                                             text::quoted(ext.empty() ? path.filename().string() : ext) +
                                             "; expected .lens (native/FlareSim), .zmx (Zemax) or .dat (pbrt)");
    const std::string bytes = readFileBytes(path, kMaxLensFileBytes);
    return parseLensBytes(bytes, format, path.string(), reporter);
}

std::filesystem::path findLensFile(const std::string& nameOrPath) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::is_regular_file(nameOrPath, ec)) return nameOrPath;
    if (nameOrPath.empty()) throw Error(ErrorKind::Input, "no lens file named ''");
    if (fs::exists(nameOrPath, ec)) throwInputError({nameOrPath}, "not a lens file (a folder or a device)");
    const bool bareName = nameOrPath.find('/') == std::string::npos && nameOrPath != "." && nameOrPath != "..";
    const std::vector<fs::path> folders = bareName ? lensSearchPath() : std::vector<fs::path>{};
    for (const fs::path& folder : folders)
        for (const fs::path& candidate : {folder / nameOrPath, folder / (nameOrPath + ".lens")})
            if (fs::is_regular_file(candidate, ec)) return candidate;
    std::string where;
    for (const fs::path& folder : folders) where += (where.empty() ? "" : ", ") + folder.string();
    if (!bareName) throwInputError({nameOrPath}, "no such file");
    throwInputError({nameOrPath}, "no such file, and no lens of that name in " +
                                      (where.empty() ? std::string("the lens search path (none: not installed, "
                                                                   "FOURIERFLARE_LENS_PATH unset)")
                                                     : where));
}

Lens loadLensAt(const std::filesystem::path& path, const std::string& zoom, Reporter* reporter) {
    Lens lens = loadLens(path, reporter);
    if (!zoom.empty()) lens = atZoom(lens, findZoomPosition(lens, zoom));
    return lens;
}

Lens loadTraceableLens(const std::filesystem::path& path, const std::string& zoom, Reporter* reporter) {
    Lens lens = loadLensAt(path, zoom, reporter);
    requireTraceable(lens);
    return lens;
}

void requireTraceable(const Lens& lens) {
    if (!lens.rotationallySymmetric())
        throw Error(ErrorKind::Input, SourceLocation{lens.file},
                    "the lens has anamorphic surfaces: the traced and shaped flares and the aberration-free "
                    "diffraction take it; the fitted ghosts (their table, fits and exports) and the traced "
                    "wavefront need a rotationally symmetric lens");
}

} // namespace ff::optics
