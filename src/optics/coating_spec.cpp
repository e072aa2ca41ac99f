#include "optics/coating_spec.h"

#include "core/text.h"
#include "optics/glass_catalog.h"

namespace ff::optics {

namespace {

constexpr const char* kForms = "valid forms: none, mgf2 [LAMBDA0_NM], stack(MATERIAL:WAVES,...) [LAMBDA0_NM]";

SourceLocation shifted(const SourceLocation& where, std::size_t offset) {
    return {where.file, where.line, where.column > 0 ? where.column + static_cast<int>(offset) : 0};
}

double parseLambda0(std::string_view s, const SourceLocation& at) {
    auto v = text::parseNumber(s);
    if (!v || *v < 100.0 || *v > 3000.0)
        throwInputError(at,
                        "expected a design wavelength in nm (100..3000) in the coating spec, got " + text::quoted(s));
    return *v;
}

} // namespace

CoatingSpec CoatingSpec::mgf2(double lambda0Nm) {
    return {{{"MgF2", 0.25}}, lambda0Nm};
}

CoatingSpec CoatingSpec::broadband(double lambda0Nm) {
    return {{{"MgF2", 0.25}, {"ZrO2", 0.5}, {"Al2O3", 0.25}}, lambda0Nm};
}

std::string CoatingSpec::str() const {
    if (bare()) return "none";
    const std::string l0 = text::roundTrip(lambda0Nm);
    if (layers.size() == 1 && layers[0].material == "MgF2" && layers[0].waves == 0.25) return "mgf2 " + l0;
    std::string s = "stack(";
    for (std::size_t i = 0; i < layers.size(); ++i) {
        if (i) s += ",";
        s += layers[i].material + ":" + text::roundTrip(layers[i].waves);
    }
    return s + ") " + l0;
}

std::string CoatingSpec::token() const {
    std::string s = str();
    for (char& c : s)
        if (c == ' ') c = '@';
    return s;
}

CoatingSpec parseCoatingSpec(std::string_view textIn, const SourceLocation& where) {
    // Split "<kind>[ |@]<lambda0>" at the first separator outside parentheses.
    std::string_view body = textIn, lambda;
    std::size_t depth = 0, lambdaOffset = 0;
    for (std::size_t i = 0; i < textIn.size(); ++i) {
        const char c = textIn[i];
        if (c == '(') ++depth;
        if (c == ')' && depth > 0) --depth;
        if (depth == 0 && (c == '@' || c == ' ' || c == '\t')) {
            body = textIn.substr(0, i);
            std::size_t j = i;
            while (j < textIn.size() && (textIn[j] == ' ' || textIn[j] == '\t' || textIn[j] == '@')) ++j;
            lambda = textIn.substr(j);
            lambdaOffset = j;
            break;
        }
    }
    const double lambda0 = lambda.empty() ? 550.0 : parseLambda0(lambda, shifted(where, lambdaOffset));
    if (text::iequals(body, "none") || body == "0") {
        if (!lambda.empty())
            throwInputError(shifted(where, lambdaOffset), "a bare surface ('none') takes no wavelength");
        return CoatingSpec::none();
    }
    if (text::iequals(body, "mgf2")) return CoatingSpec::mgf2(lambda0);
    if (text::iequals(body, "broadband")) return CoatingSpec::broadband(lambda0);
    if (text::startsWith(text::toLower(body), "stack(")) {
        if (body.back() != ')') throwInputError(shifted(where, body.size()), "expected ')' to close the coating stack");
        const std::string_view inner = body.substr(6, body.size() - 7);
        CoatingSpec spec;
        spec.lambda0Nm = lambda0;
        std::size_t offset = 6;
        for (std::string_view rawPart : text::split(inner, ',')) {
            const std::size_t lead =
                rawPart.find_first_not_of(" \t") == std::string_view::npos ? 0 : rawPart.find_first_not_of(" \t");
            const std::string_view part = text::trim(rawPart);
            const auto at = shifted(where, offset + lead);
            const auto colon = part.find(':');
            if (colon == std::string_view::npos || colon == 0)
                throwInputError(at, "expected MATERIAL:WAVES in the coating stack, got " + text::quoted(part));
            auto waves = text::parseNumber(part.substr(colon + 1));
            if (!waves || *waves <= 0.0 || *waves > 100.0)
                throwInputError(shifted(at, colon + 1), "expected a layer thickness in waves (0 < t <= 100), got " +
                                                            text::quoted(part.substr(colon + 1)));
            const std::string_view material = part.substr(0, colon);
            const GlassEntry& entry = GlassCatalog::builtin().get(material, at);
            spec.layers.push_back({entry.name, *waves});
            offset += rawPart.size() + 1;
        }
        if (spec.layers.empty()) throwInputError(where, "empty coating stack");
        return spec;
    }
    throwInputError(where, "unknown coating " + text::quoted(body) + "; " + kForms);
}

} // namespace ff::optics
