#include "core/error.h"
#include "core/units.h"
#include "optics/glass_catalog.h"
#include "optics/medium.h"

#include <gtest/gtest.h>

using namespace ff;
using namespace ff::optics;

TEST(Medium, SellmeierReproducesCatalogueNdAndVd) {
    // The catalogue lists nd and Vd next to the coefficients; re-deriving them from the Sellmeier
    // formula must agree to 1e-5 in nd and 0.05 in Vd (rounding of the printed values).
    int checked = 0;
    for (const GlassEntry& g : GlassCatalog::builtin().entries()) {
        if (g.catalogNd == 0.0) continue;
        const double nd = g.dispersion.index(lines::d);
        const double vd = (nd - 1.0) / (g.dispersion.index(lines::F) - g.dispersion.index(lines::C));
        EXPECT_NEAR(nd, g.catalogNd, 1e-5) << g.name;
        EXPECT_NEAR(vd, g.catalogVd, 0.05) << g.name;
        ++checked;
    }
    EXPECT_GE(checked, 30);
}

TEST(Medium, MgF2FollowsDodgeWithUnsquaredC) {
    // optics.md: n = 1.3815 (450 nm), 1.3785 (550 nm), 1.3767 (650 nm), printed to 4 decimals.
    const GlassEntry* mgf2 = GlassCatalog::builtin().find("mgf2");
    ASSERT_NE(mgf2, nullptr);
    EXPECT_NEAR(mgf2->dispersion.index(450), 1.3815, 6e-5);
    EXPECT_NEAR(mgf2->dispersion.index(550), 1.3785, 6e-5);
    EXPECT_NEAR(mgf2->dispersion.index(650), 1.3767, 6e-5);
}

TEST(Medium, CauchyFromAbbeHitsNdAndVdExactly) {
    // n = A + B/L^2 gives nF - nC = B (1/LF^2 - 1/LC^2) = (nd - 1)/Vd by construction.
    const Medium m = Medium::fromNdVd(1.67, 47.1);
    EXPECT_NEAR(m.index(lines::d), 1.67, 1e-14);
    EXPECT_NEAR((m.index(lines::d) - 1.0) / (m.index(lines::F) - m.index(lines::C)), 47.1, 1e-9);
    EXPECT_GT(m.index(450), m.index(650)); // normal dispersion
}

TEST(Medium, CauchyErrorAgainstSellmeierMatchesReference) {
    // optics.md: Cauchy(nd, Vd) minus Sellmeier at 400 nm: N-BK7 +0.9e-4, F2 -21.7e-4, N-SF11 -70.4e-4.
    const struct {
        const char* name;
        double diff;
    } cases[] = {{"N-BK7", 0.9e-4}, {"F2", -21.7e-4}, {"N-SF11", -70.4e-4}};
    for (const auto& c : cases) {
        const GlassEntry* g = GlassCatalog::builtin().find(c.name);
        ASSERT_NE(g, nullptr);
        const double nd = g->dispersion.index(lines::d);
        const Medium cauchy = Medium::fromNdVd(nd, abbeNumber(g->dispersion));
        EXPECT_NEAR(cauchy.index(400) - g->dispersion.index(400), c.diff, 0.06e-4) << c.name;
    }
}

TEST(Medium, ZeroAbbeMeansNonDispersive) {
    const Medium m = Medium::fromNdVd(1.6, 0.0);
    EXPECT_EQ(m.index(400), 1.6);
    EXPECT_EQ(m.index(700), 1.6);
}

TEST(GlassCatalog, LookupIsCaseInsensitiveAndResolvesAliases) {
    const auto& cat = GlassCatalog::builtin();
    ASSERT_NE(cat.find("n-bk7"), nullptr);
    ASSERT_NE(cat.find("SK16"), nullptr);
    EXPECT_EQ(cat.find("SK16")->name, "N-SK16");
    EXPECT_EQ(cat.find("XYZ-123"), nullptr);
}

TEST(GlassCatalog, UnknownNameListsClosestNames) {
    try {
        GlassCatalog::builtin().get("NBK7", {"a.lens", 3, 9});
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "a.lens:3:9: unknown glass 'NBK7'; did you mean N-BK7, N-ZK7 or N-BAK1? "
                                         "(the catalogue is data/glass/; give 'nd Vd' instead for other glasses)");
    }
}
