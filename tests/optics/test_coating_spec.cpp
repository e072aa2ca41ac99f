#include "core/error.h"
#include "optics/coating_spec.h"

#include <gtest/gtest.h>

using namespace ff;
using namespace ff::optics;

TEST(CoatingSpec, ParsesEveryForm) {
    const SourceLocation at{"c.lens", 1, 10};
    EXPECT_EQ(parseCoatingSpec("none", at), CoatingSpec::none());
    EXPECT_EQ(parseCoatingSpec("mgf2", at), CoatingSpec::mgf2(550.0));
    EXPECT_EQ(parseCoatingSpec("mgf2 600", at), CoatingSpec::mgf2(600.0));
    EXPECT_EQ(parseCoatingSpec("MgF2@480", at), CoatingSpec::mgf2(480.0));
    const CoatingSpec s = parseCoatingSpec("stack(mgf2:0.25, zro2:0.5, al2o3:0.25) 520", at);
    ASSERT_EQ(s.layers.size(), 3u);
    EXPECT_EQ(s.layers[1].material, "ZrO2"); // canonical catalogue name
    EXPECT_EQ(s.layers[1].waves, 0.5);
    EXPECT_EQ(s.lambda0Nm, 520.0);
    EXPECT_EQ(parseCoatingSpec(s.str(), at), s);
    EXPECT_EQ(parseCoatingSpec(s.token(), at), s);
    EXPECT_EQ(CoatingSpec::mgf2(550).str(), "mgf2 550");
}

TEST(CoatingSpec, RejectsMalformedSpecsWithColumns) {
    const SourceLocation at{"c.lens", 4, 10};
    const std::pair<const char*, const char*> cases[] = {
        {"mgf2 abc", "c.lens:4:15: expected a design wavelength in nm (100..3000) in the coating spec, got 'abc'"},
        {"stack(MgF2:0.25", "c.lens:4:25: expected ')' to close the coating stack"},
        {"stack(MgF2)", "c.lens:4:16: expected MATERIAL:WAVES in the coating stack, got 'MgF2'"},
        {"stack(Mgf3:0.25)", "c.lens:4:16: unknown glass 'Mgf3'; did you mean MgF2? "
                             "(the catalogue is data/glass/; give 'nd Vd' instead for other glasses)"},
        {"stack(MgF2:0.25, Unobtainium:0.5)",
         "c.lens:4:27: unknown glass 'Unobtainium'; valid names: N-BK7, N-SF11, F2, N-F2, "
         "N-SK16, N-SSK2, N-SK2, F5, N-SK15, K10, N-BASF2, N-ZK7, N-LAF33, SF1, N-SF1, N-SK4, "
         "N-BAK1, N-BALF4, SF5, N-SF5, N-LAK9, N-SF6, N-LASF9, N-FK5, N-BAF10, SF2, LF5, N-SF10, "
         "N-BAK4, N-SK14, N-LAK22, N-SF2, SF4, N-SF4, N-KF9, N-K5, MgF2, ZrO2, Al2O3, SK16 "
         "(the catalogue is data/glass/; give 'nd Vd' instead for other glasses)"},
        {"stack(MgF2:-1)", "c.lens:4:21: expected a layer thickness in waves (0 < t <= 100), got '-1'"},
        {"none 550", "c.lens:4:15: a bare surface ('none') takes no wavelength"},
    };
    for (const auto& [spec, expected] : cases) {
        try {
            parseCoatingSpec(spec, at);
            ADD_FAILURE() << "accepted " << spec;
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), expected) << spec;
        }
    }
}
