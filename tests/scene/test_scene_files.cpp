// The lights file and the ghost list: whatever their bytes, a list or ff::Error (Input) naming the
// file, never another exception (inputs the fuzzers found are kept here as regressions).

#include "core/error.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <string>

using namespace ff;

namespace {

// The error's message, or "" when `read` returned.
template <class Read>
std::string inputError(Read read) {
    try {
        read();
    } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
        EXPECT_EQ(e.where().file, "f.json") << e.what();
        return e.what();
    }
    return "";
}

} // namespace

TEST(SceneFiles, LightsAndGhostsReadTheirFields) {
    const auto lights =
        scene::parseLightsJson(R"({"lights": [{"x": 1.5, "y": 2, "flux": [1, 2, 3]}, {"x": 0, "y": 0}]})", "f.json");
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights[0].xPx, 1.5);
    EXPECT_EQ(lights[0].flux[2], 3.0);
    EXPECT_EQ(lights[1].flux[0], 1.0); // default: a unit light
    const auto ghosts = scene::parseGhostsJson(
        R"({"ghosts": [{"x": 4, "y": 5, "profile": "cos2", "widthX": 3, "widthY": [1, 2, 3], "flux": 0.5}]})",
        "f.json");
    ASSERT_EQ(ghosts.size(), 1u);
    EXPECT_EQ(ghosts[0].widthY[1], 2.0);
    EXPECT_EQ(ghosts[0].flux[0], 0.5);
}

TEST(SceneFiles, NumbersBeyondDoubleAndValuesOfTheWrongTypeAreInputErrors) {
    // A number past double's range (the JSON library throws out_of_range, not a parse error).
    EXPECT_NE(inputError([] { scene::parseLightsJson("1e348", "f.json"); }).find("not valid JSON"), std::string::npos);
    EXPECT_NE(inputError([] { scene::parseLightsJson(R"({"lights": [{"x": 1e400, "y": 0}]})", "f.json"); }), "");
    // A profile that is not a string (type_error from the library's value()).
    EXPECT_NE(inputError([] {
                  scene::parseGhostsJson(
                      R"({"ghosts": [{"x": 1, "y": 2, "profile": 3, "widthX": 1, "widthY": 1, "flux": 1}]})", "f.json");
              }).find("unexpected JSON"),
              std::string::npos);
    EXPECT_NE(inputError([] { scene::parseGhostsJson(R"({"ghosts": 7})", "f.json"); }), "");
}
