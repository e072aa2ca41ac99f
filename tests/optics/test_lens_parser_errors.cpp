// Malformed lens files: each must fail with one precise message naming file:line:column and what
// was expected. The expected strings are written out in full so a change to any message is seen.

#include "core/error.h"
#include "optics/lens_parser.h"

#include <gtest/gtest.h>

using namespace ff;
using namespace ff::optics;

namespace {

// A valid lens with a placeholder: surfaces start on line 3.
const std::string kHead = "name: t\nsurfaces:\n";
const std::string kTail = "  stop 2 1 0 5\n  50 4 1.5 60 10\n  -50 40 1 0 10\n";

struct BadCase {
    const char* label;
    std::string text;
    const char* expected; // full what(): "t.lens:L:C: message"
};

std::vector<BadCase> badCases() {
    return {
        {"short row", kHead + "  10 2 1.5\n" + kTail,
         "t.lens:3:12: short row: found 3 column(s), expected radius thickness ior abbe semi_ap [coating]  (or: radius "
         "thickness GLASS semi_ap [coating])"},
        {"short glass row", kHead + "  10 2 N-BK7\n" + kTail,
         "t.lens:3:14: short row: found 3 column(s), expected radius thickness ior abbe semi_ap [coating]  (or: radius "
         "thickness GLASS semi_ap [coating])"},
        {"non-number thickness", kHead + "  10 abc 1.5 60 5 1\n" + kTail,
         "t.lens:3:6: expected a number for 'thickness', got 'abc'"},
        {"non-number radius", kHead + "  1O 2 1.5 60 5 1\n" + kTail,
         "t.lens:3:3: expected a number, 'inf' or 'stop' for 'radius', got '1O'"},
        {"trailing junk in a number", kHead + "  10 2 1.5 60 5.0mm 1\n" + kTail,
         "t.lens:3:15: expected a number for 'semi_ap', got '5.0mm'"},
        {"negative semi-aperture", kHead + "  10 2 1.5 60 -5 1\n" + kTail,
         "t.lens:3:15: negative semi-aperture '-5'; expected the clear semi-diameter in mm (>= 0)"},
        {"index out of range", kHead + "  10 2 0.5 60 5 1\n" + kTail,
         "t.lens:3:8: expected a refractive index between 1 and 4 for 'ior', got '0.5'"},
        {"negative abbe", kHead + "  10 2 1.5 -3 5 1\n" + kTail,
         "t.lens:3:12: expected an Abbe number between 0 and 200 (0 = no dispersion), got '-3'"},
        {"fractional coating layers", kHead + "  10 2 1.5 60 5 1.5\n" + kTail,
         "t.lens:3:17: expected a whole number of coating layers (0..20) for 'coating', got '1.5'"},
        {"unknown word after the columns", kHead + "  10 2 1.5 60 5 1 sto\n" + kTail,
         "t.lens:3:19: unexpected 'sto' after the surface columns; expected 'stop', a shape (sph, cyl_x, cyl_y, "
         "toric), conic=K, asph=A4,A6,..., biconic=RX[,KX], coating=SPEC, grin_r=... or grin_z=..."},
        {"unknown surface option", kHead + "  10 2 1.5 60 5 1 conik=1\n" + kTail,
         "t.lens:3:19: unknown surface option 'conik'; valid options: conic=K, asph=A4,A6,..., biconic=RX[,KX], "
         "coating=SPEC, grin_r=A1:D1,..., grin_z=B1:D1,..."},
        {"biconic radius not a number", kHead + "  10 2 1.5 60 5 1 biconic=x\n" + kTail,
         "t.lens:3:27: expected a number for the x-z section's radius in 'biconic=RX,KX', got 'x'"},
        {"biconic with three values", kHead + "  10 2 1.5 60 5 1 biconic=1,2,3\n" + kTail,
         "t.lens:3:27: expected 'biconic=RX' or 'biconic=RX,KX'"},
        {"biconic on a cylinder", kHead + "  10 2 1.5 60 5 1 cyl_x biconic=20\n" + kTail,
         "t.lens:3:25: 'biconic=' on a cyl_x surface (one shape a row)"},
        {"gradient without dispersion", kHead + "  10 2 1.5 60 5 1 grin_r=-0.002\n" + kTail,
         "t.lens:3:26: the gradient coefficient '-0.002' has no dispersion: write VALUE:D (c(lambda) = VALUE + D "
         "(1/L^2 - 1/Ld^2), L in um; D = 0 for none)"},
        {"gradient dispersion not a number", kHead + "  10 2 1.5 60 5 1 grin_r=-0.002:x\n" + kTail,
         "t.lens:3:33: expected a number after ':' in '-0.002:x'"},
        {"gradient twice", kHead + "  10 2 1.5 60 5 1 grin_z=0.01:0 grin_z=0.02:0\n" + kTail,
         "t.lens:3:33: 'grin_z' given twice in one row"},
        // n0(380 nm) = 1.517580 (Cauchy through nd 1.5, Vd 60) less 0.1 r^2: below 1 first at the
        // grid's r = 5 x 15 / 32 mm: 1.517580 - 0.549316 = 0.968264.
        {"gradient below 1", kHead + "  10 2 1.5 60 5 1 grin_r=-0.1:0\n" + kTail,
         "t.lens:3:19: the graded index is 0.9682637443489721 at r = 2.344 mm, z = 0.000 mm, 380.0 nm, inside the "
         "element after surface 1: it must stay above 1 and finite"},
        {"gradient before the sensor",
         kHead + "  10 2 1.5 60 5 1\n  stop 2 1 0 5\n  50 4 1.5 60 10\n  -50 40 1 0 10 grin_z=0.01:0\n",
         "t.lens:6:17: a graded index after the last surface: the space before the sensor must be homogeneous"},
        {"bad conic", kHead + "  10 2 1.5 60 5 1 conic=x\n" + kTail,
         "t.lens:3:25: expected a number for 'conic', got 'x'"},
        {"bad asphere term", kHead + "  10 2 1.5 60 5 1 asph=1e-5,zz\n" + kTail,
         "t.lens:3:29: expected a number in 'asph=A4,A6,...', got 'zz'"},
        {"bad coating spec", kHead + "  10 2 1.5 60 5 1 coating=mgf3\n" + kTail,
         "t.lens:3:27: unknown coating 'mgf3'; valid forms: none, mgf2 [LAMBDA0_NM], stack(MATERIAL:WAVES,...) "
         "[LAMBDA0_NM]"},
        {"unknown glass", kHead + "  10 2 NBK7 5 1\n" + kTail,
         "t.lens:3:8: unknown glass 'NBK7'; did you mean N-BK7, N-ZK7 or N-BAK1? (the catalogue is data/glass/; give "
         "'nd Vd' instead for other glasses)"},
        {"unknown header key", "focal: 50\n" + kHead + kTail,
         "t.lens:1:1: unknown header key 'focal'; did you mean focal_length?"},
        {"unknown header key, nothing close", "lens_maker: x\n" + kHead + kTail,
         "t.lens:1:1: unknown header key 'lens_maker'; valid keys: name, focal_length, f_number, sensor, "
         "aperture_blades, "
         "blade_rotation, coating, source, patent, zoom_positions, surfaces"},
        {"duplicate header key", "name: a\n" + kHead + kTail, "t.lens:2:1: duplicate header key 'name'"},
        {"header key after surfaces", kHead + kTail + "f_number: 2\n",
         "t.lens:6:1: header key 'f_number:' after 'surfaces:'; header keys must come before the surface rows"},
        {"row before surfaces", "name: t\n  10 2 1.5 60 5 1\nsurfaces:\n" + kTail,
         "t.lens:2:3: surface row before 'surfaces:'; add a line 'surfaces:' above the rows"},
        {"no surfaces section", "name: t\n",
         "t.lens:2: no 'surfaces:' section: expected a line 'surfaces:' followed by one row per surface"},
        {"empty surfaces section", kHead, "t.lens:2:1: the 'surfaces:' section has no surface rows"},
        {"junk after surfaces", "surfaces: now\n" + kTail, "t.lens:1:11: unexpected 'now' after 'surfaces:'"},
        {"no stop and no semi-aperture", kHead + "  50 4 1.5 60 0\n  -50 40 1 0 0\n",
         "t.lens:2:1: no aperture stop, and no surface limits the axial beam (no semi-aperture is given): mark one "
         "surface as the stop (a 'stop' row for a flat stop, or the word 'stop' after the columns of a curved "
         "surface)"},
        {"two stops", kHead + "  20 1 1 0 5 0 stop\n" + kTail,
         "t.lens:4:3: a second aperture stop (surface 2); surface 1 is already the stop"},
        {"stop without opening", kHead + "  stop 2 1 0 0\n  50 4 1.5 60 10\n  -50 40 1 0 10\n",
         "t.lens:3:3: the stop has no semi-aperture (0) and the header gives no 'f_number:'; give one of them to set "
         "the aperture"},
        {"negative image distance", kHead + "  stop 2 1 0 5\n  50 4 1.5 60 10\n  -50 -2 1 0 10\n",
         "t.lens:5:3: the last thickness (distance to the sensor) must be positive, got -2; use 'auto' for the "
         "paraxial focus"},
        {"auto not last", kHead + "  stop auto 1 0 5\n  50 4 1.5 60 10\n  -50 40 1 0 10\n",
         "t.lens:3:8: 'auto' thickness is only allowed on the last row (the distance to the sensor)"},
        {"zoom list without positions", kHead + "  stop 2,3 1 0 5\n  50 4 1.5 60 10\n  -50 40 1 0 10\n",
         "t.lens:3:8: a thickness list (zoom) needs 'zoom_positions:' in the header"},
        {"zoom list of the wrong length",
         "zoom_positions: a b c\n" + kHead + "  stop 2,3 1 0 5\n  50 4 1.5 60 10\n  -50 40 1 0 10\n",
         "t.lens:4:8: expected 3 thicknesses (one per zoom position), got 2"},
        {"bad sensor", "sensor: 36by24\n" + kHead + kTail,
         "t.lens:1:9: expected the sensor size as WIDTHxHEIGHT in mm (e.g. 36x24), got '36by24'"},
        {"two-blade iris", "aperture_blades: 2\n" + kHead + kTail,
         "t.lens:1:18: expected a blade count of 0 (circular) or 3..64, got '2'"},
        {"absurd f-number", "f_number: 0\n" + kHead + kTail,
         "t.lens:1:11: 'f_number' must be between 0.3 and 1000, got '0'"},
        {"junk after a header value", "focal_length: 50 mm\n" + kHead + kTail,
         "t.lens:1:18: unexpected 'mm' after the value of 'focal_length:'"},
        {"nul byte", kHead + std::string("  10 2 1.5\0 60 5 1\n", 19) + kTail,
         "t.lens:3:11: not a text file (NUL byte)"},
        {"control character", kHead + "  10 2 1.5\x07 60 5 1\n" + kTail,
         "t.lens:3:11: unexpected control character '\\x07'; is this a text file?"},
        {"invalid utf-8", "name: caf\xE9\n" + kHead + kTail,
         "t.lens:1:10: invalid UTF-8 byte; is this a text file (or UTF-16, which only .zmx may use)?"},
    };
}

} // namespace

TEST(LensParserErrors, EachMalformedInputGetsOnePreciseMessage) {
    const auto cases = badCases();
    ASSERT_GE(cases.size(), 20u);
    for (const BadCase& c : cases) {
        try {
            parseLensText(c.text, "t.lens");
            ADD_FAILURE() << c.label << ": no error for input:\n" << c.text;
        } catch (const Error& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Input) << c.label;
            EXPECT_EQ(std::string(e.what()), c.expected) << c.label << "; input:\n" << c.text;
        }
    }
}

TEST(LensParserErrors, ValidBaseParses) {
    // The cases above differ from this file in one place each.
    EXPECT_NO_THROW(parseLensText(kHead + kTail, "t.lens"));
}
