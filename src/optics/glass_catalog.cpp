#include "optics/glass_catalog.h"

#include "core/text.h"
#include "core/units.h"

namespace ff::optics {

// Defined in the generated file that embeds data/glass/*.glass (cmake/FFEmbed.cmake).
std::string_view embedded(std::string_view name);

namespace {

double numberAt(const text::Token& tok, const SourceLocation& line, const char* what) {
    auto v = text::parseNumber(tok.text);
    if (!v)
        throwInputError({line.file, line.line, tok.column},
                        std::string("expected a number for '") + what + "', got " + text::quoted(tok.text));
    return *v;
}

} // namespace

const GlassCatalog& GlassCatalog::builtin() {
    static const GlassCatalog catalog = [] {
        GlassCatalog c;
        for (const char* file : {"schott.glass", "coating-materials.glass"})
            c.addFromText(embedded(file), std::string("data/glass/") + file);
        return c;
    }();
    return catalog;
}

void GlassCatalog::addFromText(std::string_view text, const std::string& sourceName) {
    int lineNo = 0;
    for (std::string_view line : text::split(text, '\n')) {
        ++lineNo;
        const auto tokens = text::tokenize(line);
        if (tokens.empty()) continue;
        const SourceLocation at{sourceName, lineNo, tokens[0].column};
        if (tokens[0].text == "alias") {
            if (tokens.size() != 3) throwInputError(at, "expected 'alias NAME TARGET'");
            aliases_.emplace_back(std::string(tokens[1].text), std::string(tokens[2].text));
            continue;
        }
        if (tokens.size() < 2) throwInputError(at, "expected 'NAME MODEL coefficients...'");
        GlassEntry e;
        e.name = std::string(tokens[0].text);
        e.source = sourceName;
        const std::string_view model = tokens[1].text;
        auto num = [&](std::size_t i, const char* what) { return numberAt(tokens[i], at, what); };
        if (model == "sellmeier" || model == "sellmeier-c-um") {
            if (tokens.size() != 8 && tokens.size() != 10)
                throwInputError(at, "expected 6 Sellmeier coefficients (and optionally nd Vd) after '" +
                                        std::string(model) + "', got " + std::to_string(tokens.size() - 2) + " values");
            std::array<double, 3> b{}, c{};
            for (int i = 0; i < 3; ++i) {
                b[i] = num(2 + 2 * i, "B");
                c[i] = num(3 + 2 * i, "C");
                if (model == "sellmeier-c-um") c[i] *= c[i];
            }
            e.dispersion = Dispersion::sellmeier(b, c);
            if (tokens.size() == 10) {
                e.catalogNd = num(8, "nd");
                e.catalogVd = num(9, "Vd");
            }
        } else if (model == "constant") {
            if (tokens.size() != 3) throwInputError(at, "expected one index after 'constant'");
            e.dispersion = Dispersion::constant(num(2, "n"));
        } else {
            throwInputError({sourceName, lineNo, tokens[1].column},
                            "unknown dispersion model " + text::quoted(model) +
                                "; valid choices are: sellmeier, sellmeier-c-um, constant");
        }
        entries_.push_back(std::move(e));
    }
}

const GlassEntry* GlassCatalog::find(std::string_view name) const {
    std::string target(name);
    for (const auto& [alias, to] : aliases_)
        if (text::iequals(alias, name)) target = to;
    for (const auto& e : entries_)
        if (text::iequals(e.name, target)) return &e;
    return nullptr;
}

const GlassEntry& GlassCatalog::get(std::string_view name, const SourceLocation& where) const {
    if (const GlassEntry* e = find(name)) return *e;
    throwInputError(where, "unknown glass " + text::quoted(name) + "; " + text::suggestion(name, names(), "names") +
                               " (the catalogue is data/glass/; give 'nd Vd' instead for other glasses)");
}

Medium GlassCatalog::medium(std::string_view name, const SourceLocation& where) const {
    const GlassEntry& e = get(name, where);
    Medium m;
    m.glass = e.name;
    m.dispersion = e.dispersion;
    m.nd = e.dispersion.index(ff::lines::d);
    m.vd = abbeNumber(e.dispersion);
    return m;
}

std::vector<std::string> GlassCatalog::names() const {
    std::vector<std::string> n;
    for (const auto& e : entries_) n.push_back(e.name);
    for (const auto& a : aliases_) n.push_back(a.first);
    return n;
}

} // namespace ff::optics
