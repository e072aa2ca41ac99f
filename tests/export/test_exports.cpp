#include "export/engine_exports.h"
#include "optics/lens_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <yaml-cpp/yaml.h>

#include "test_support.h"

using namespace ff;
using namespace ff::exporting;

namespace {

const ghosts::GhostTable& table(int blades) {
    static std::map<int, ghosts::GhostTable> tables;
    auto it = tables.find(blades);
    if (it == tables.end()) {
        optics::Lens lens = optics::loadLens(test::lensPath("cooke-triplet-50mm-f5.lens"));
        lens.apertureBlades = blades;
        ghosts::TableSettings s;
        s.grid = 12;
        s.angles = 11;
        s.maxAngleDeg = 14.0;
        it = tables.emplace(blades, ghosts::buildGhostTable(lens, s)).first;
    }
    return it->second;
}

std::vector<std::string> csvFields(const std::string& line) {
    std::vector<std::string> f;
    std::string cur;
    bool quoted = false;
    for (char c : line) {
        if (c == '"')
            quoted = !quoted;
        else if (c == ',' && !quoted)
            f.push_back(cur), cur.clear();
        else
            cur += c;
    }
    f.push_back(cur);
    return f;
}

} // namespace

TEST(Exports, CsvIsAnUnrealDataTableWithTheMappedNumbers) {
    const auto& t = table(0);
    const auto ghosts = summarize(t, 7.0);
    std::istringstream in(toCsv(t, 7.0, 0));
    std::string line;
    std::getline(in, line);
    const auto header = csvFields(line);
    ASSERT_EQ(header[0], "Name");
    std::size_t rows = 0;
    while (std::getline(in, line)) {
        const auto f = csvFields(line);
        ASSERT_EQ(f.size(), header.size()) << line;
        const GhostSummary& g = ghosts[rows++];
        EXPECT_EQ(f[0], g.id);
        EXPECT_DOUBLE_EQ(std::stod(f[5]), g.magnification);
        EXPECT_DOUBLE_EQ(std::stod(f[9]), g.flux[1]);
        double r = -1, gg = -1, b = -1;
        int consumed = 0;
        ASSERT_EQ(std::sscanf(f[11].c_str(), "(R=%lf,G=%lf,B=%lf,A=1.0)%n", &r, &gg, &b, &consumed), 3) << f[11];
        EXPECT_EQ(static_cast<std::size_t>(consumed), f[11].size()) << f[11];
        EXPECT_NEAR(std::max({r, gg, b}), 1.0, 1e-4);
        EXPECT_NEAR(std::stod(f[7]), g.radiusMm / (0.5 * t.sensorSizeMm.second), 1e-12);
    }
    EXPECT_EQ(rows, ghosts.size());
    EXPECT_GT(rows, 5u);
}

TEST(Exports, UnityAssetParsesAndMapsPositionScaleTintAndShape) {
    for (int blades : {0, 6}) {
        const auto& t = table(blades);
        const auto ghosts = summarize(t, 7.0, 10);
        const YAML::Node doc = YAML::Load(toUnityAsset(t, 7.0, 10, "Cooke"));
        const YAML::Node mb = doc["MonoBehaviour"];
        ASSERT_TRUE(mb);
        EXPECT_EQ(mb["m_Name"].as<std::string>(), "Cooke");
        EXPECT_EQ(mb["m_Script"]["guid"].as<std::string>(), "877e1507ae8d81c40bf1b94c1a86036f");
        const YAML::Node el = mb["elements"];
        ASSERT_EQ(el.size(), ghosts.size());
        for (std::size_t i = 0; i < ghosts.size(); ++i) {
            // position = 1 - m; uniformScale = 20 r / H; tint = colour with its largest channel 1.
            EXPECT_NEAR(el[i]["position"].as<double>(), 1.0 - ghosts[i].magnification, 1e-4);
            EXPECT_NEAR(el[i]["uniformScale"].as<double>(), 20.0 * ghosts[i].radiusMm / t.sensorSizeMm.second, 1e-4);
            const double r = el[i]["tint"]["r"].as<double>(), g = el[i]["tint"]["g"].as<double>(),
                         b = el[i]["tint"]["b"].as<double>();
            EXPECT_NEAR(std::max({r, g, b}), 1.0, 1e-4);
            EXPECT_EQ(el[i]["flareType"].as<int>(), blades ? 2 : 1);
            if (blades) {
                EXPECT_EQ(el[i]["m_SideCount"].as<int>(), 6);
            }
            EXPECT_GE(el[i]["m_LocalIntensity"].as<double>(), 0.0);
            EXPECT_LE(el[i]["m_LocalIntensity"].as<double>(), 1.0);
        }
    }
}

TEST(Exports, UnrealPresetMapsMagnificationToAlpha) {
    const auto& t = table(0);
    const auto ghosts = summarize(t, 7.0, 8);
    const std::string text = toUnrealPreset(t, 7.0);
    std::size_t found = 0;
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
        if (line.rfind("LensFlareTints[", 0) != 0) continue;
        unsigned i = 99;
        double r, g, b, a;
        ASSERT_EQ(std::sscanf(line.c_str(), "LensFlareTints[%u]=(R=%lf,G=%lf,B=%lf,A=%lf)", &i, &r, &g, &b, &a), 5)
            << line;
        ASSERT_EQ(i, found++);
        if (i < ghosts.size()) {
            EXPECT_NEAR(a, (ghosts[i].magnification + 7.0) / 14.0, 1e-4);
        }
    }
    EXPECT_EQ(found, 8u);
    EXPECT_NE(text.find("LensFlareBokehSize="), std::string::npos);
}
