#include "optics/dat_importer.h"

#include "core/text.h"
#include "optics/lens_parser.h"
#include "optics/lens_validation.h"

namespace ff::optics {

Lens importDat(std::string_view textIn, const std::string& fileName, Reporter* reporterIn) {
    Reporter& reporter = orNull(reporterIn);
    checkIsText(textIn, fileName);
    Lens lens;
    lens.file = fileName;
    lens.format = "dat";
    std::vector<double> second; // thickness or axial position, as read
    int lineNo = 0, lastLine = 0;
    for (std::string_view line : text::split(textIn, '\n')) {
        ++lineNo;
        const auto t = text::tokenize(line);
        if (t.empty()) {
            // Keep the first comment line as the lens name (pbrt files open with a description).
            const auto trimmed = text::trim(line);
            if (lens.name.empty() && lens.surfaces.empty() && text::startsWith(trimmed, "#"))
                lens.name = std::string(text::trim(trimmed.substr(1)));
            continue;
        }
        lastLine = lineNo;
        if (t.size() != 4)
            throwInputError({fileName, lineNo,
                             t.size() > 4 ? t[4].column : t.back().column + static_cast<int>(t.back().text.size()) + 1},
                            "expected 4 values per row (radius thickness eta aperture-diameter), found " +
                                std::to_string(t.size()));
        double v[4];
        static constexpr const char* kNames[] = {"radius", "thickness", "eta", "aperture diameter"};
        for (int i = 0; i < 4; ++i) {
            auto x = text::parseNumber(t[i].text);
            if (!x)
                throwInputError({fileName, lineNo, t[i].column}, std::string("expected a number for '") + kNames[i] +
                                                                     "', got " + text::quoted(t[i].text));
            v[i] = *x;
        }
        if (v[2] != 0.0 && (v[2] < 1.0 || v[2] > 4.0))
            throwInputError({fileName, lineNo, t[2].column},
                            "expected eta 0 (air) or an index between 1 and 4, got " + text::quoted(t[2].text));
        if (v[3] < 0.0)
            throwInputError({fileName, lineNo, t[3].column}, "negative aperture diameter " + text::quoted(t[3].text));
        if (lens.surfaces.size() >= 1000)
            throwInputError({fileName, lineNo, 1}, "more than 1000 surfaces; this is not a lens prescription");
        Surface s;
        s.origin = {fileName, lineNo, t[0].column};
        s.radius = v[0];
        s.stop = s.flatStopRow = (v[0] == 0.0);
        s.medium = (v[2] == 0.0 || v[2] == 1.0) ? Medium::air() : Medium::fromNdVd(v[2], 0.0);
        s.semiAperture = 0.5 * v[3];
        const bool beforeAir = lens.surfaces.empty() || lens.surfaces.back().medium.isAir();
        s.coatingLayers = (beforeAir != s.medium.isAir()) ? 1 : 0;
        second.push_back(v[1]);
        lens.surfaces.push_back(std::move(s));
    }
    if (lens.surfaces.empty())
        throwInputError({fileName, lineNo, 0}, "no lens rows (expected: radius thickness eta aperture-diameter)");

    // Axial positions grow strictly from row to row; real thicknesses (glass, air, glass...) do not.
    bool positions = second.size() >= 3;
    for (std::size_t i = 1; i < second.size() && positions; ++i) positions = second[i] > second[i - 1];
    const SourceLocation section{fileName, lastLine, 0};
    if (positions) {
        for (std::size_t i = 0; i + 1 < second.size(); ++i) lens.surfaces[i].thickness = second[i + 1] - second[i];
        lens.imageDistanceAuto = true;
        reporter.note(section, "the second column grows monotonically: read as axial positions, not thicknesses; "
                               "the sensor is placed at the paraxial focus");
    } else {
        for (std::size_t i = 0; i < second.size(); ++i) lens.surfaces[i].thickness = second[i];
        if (second.back() == 0.0) lens.imageDistanceAuto = true;
    }
    validateLens(lens, section, reporter);
    return lens;
}

} // namespace ff::optics
