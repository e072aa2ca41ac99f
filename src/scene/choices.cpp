#include "scene/choices.h"

#include "core/error.h"
#include "core/text.h"

#include <array>
#include <string>
#include <utility>

namespace ff::scene {

namespace {

template <typename E, std::size_t N>
E named(const std::array<std::pair<const char*, E>, N>& names, std::string_view name, std::string_view what) {
    std::string list;
    for (std::size_t i = 0; i < N; ++i) {
        if (name == names[i].first) return names[i].second;
        list += std::string(i == 0 ? "" : i + 1 == N ? " or " : ", ") + names[i].first;
    }
    throw Error(ErrorKind::Usage, std::string(what) + " is " + list + ", got " + text::quoted(std::string(name)));
}

template <typename E, std::size_t N>
const char* nameOf(const std::array<std::pair<const char*, E>, N>& names, E e) {
    for (const auto& [n, v] : names)
        if (v == e) return n;
    return "?";
}

constexpr std::array<std::pair<const char*, RenderMode>, 5> kModes{{{"traced", RenderMode::Traced},
                                                                    {"shaped", RenderMode::Shaped},
                                                                    {"fitted", RenderMode::Fitted},
                                                                    {"fourier", RenderMode::Fourier},
                                                                    {"diffraction", RenderMode::Diffraction}}};
constexpr std::array<std::pair<const char*, GhostModel>, 3> kModels{
    {{"shaped", GhostModel::Shaped}, {"gaussian", GhostModel::Gaussian}, {"cos2", GhostModel::Cos2}}};
constexpr std::array<std::pair<const char*, DiffractionRule>, 3> kRules{
    {{"off", DiffractionRule::Off}, {"physical", DiffractionRule::Physical}, {"traced", DiffractionRule::Traced}}};

} // namespace

const char* toString(RenderMode m) {
    return nameOf(kModes, m);
}
const char* toString(GhostModel m) {
    return nameOf(kModels, m);
}
const char* toString(DiffractionRule r) {
    return nameOf(kRules, r);
}

RenderMode renderModeNamed(std::string_view name, std::string_view what) {
    return named(kModes, name, what);
}
GhostModel ghostModelNamed(std::string_view name, std::string_view what) {
    return named(kModels, name, what);
}
DiffractionRule diffractionNamed(std::string_view name, std::string_view what) {
    return named(kRules, name, what);
}

} // namespace ff::scene
