#include "core/text.h"

#include <gtest/gtest.h>

using namespace ff::text;

TEST(Text, ParseNumberAcceptsPlainDecimals) {
    EXPECT_EQ(parseNumber("1.5"), 1.5);
    EXPECT_EQ(parseNumber("-2e-3"), -2e-3);
    EXPECT_EQ(parseNumber("+4"), 4.0);
    EXPECT_EQ(parseNumber("0"), 0.0);
    EXPECT_EQ(parseNumber(".5"), 0.5);
}

TEST(Text, ParseNumberRejectsJunkSpecialsAndOverflow) {
    for (const char* bad : {"", "abc", "1.5x", "1,5", "nan", "inf", "-inf", "1e999", "--1", "+-1", "+", "0x10", "1 2"})
        EXPECT_FALSE(parseNumber(bad).has_value()) << "accepted '" << bad << "'";
}

TEST(Text, ParseIntIsStrictAndNonNegative) {
    EXPECT_EQ(parseInt("12"), 12);
    EXPECT_FALSE(parseInt("-1"));
    EXPECT_FALSE(parseInt("1.0"));
    EXPECT_FALSE(parseInt("99999999999"));
}

TEST(Text, TokenizeKeepsColumnsAndStopsAtComments) {
    const auto t = tokenize("  84.0\t10.6  # comment 3");
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t[0].text, "84.0");
    EXPECT_EQ(t[0].column, 3);
    EXPECT_EQ(t[1].text, "10.6");
    EXPECT_EQ(t[1].column, 8);
    const auto u = tokenize("name#2 x");
    ASSERT_EQ(u.size(), 2u);
    EXPECT_EQ(u[0].text, "name#2");
}

TEST(Text, EditDistanceAndClosestNames) {
    EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
    EXPECT_EQ(editDistance("N-BK7", "n-bk7"), 0u);
    const auto c = closestNames("NBK7", {"N-SF11", "N-BK7", "F2", "N-BAK1"}, 2);
    ASSERT_EQ(c.size(), 2u);
    EXPECT_EQ(c[0], "N-BK7");
}

TEST(Text, QuotedEscapesControlCharactersAndShortens) {
    EXPECT_EQ(ff::text::quoted("a\x01"
                               "b"),
              "'a\\x01b'");
    EXPECT_EQ(ff::text::quoted(std::string(50, 'x')), "'" + std::string(40, 'x') + "...'");
}

TEST(Text, RoundTripReadsBackExactly) {
    for (double v : {0.1, 1.0 / 3.0, 123456.789e-12, -42.0}) EXPECT_EQ(*parseNumber(roundTrip(v)), v);
}

TEST(Text, PrintableEscapesEverythingButValidUtf8AndLineBreaks) {
    using ff::text::printable;
    EXPECT_EQ(printable("plain, caf\xc3\xa9, \xe2\x82\xac, \xf0\x9f\x94\x86\n\tend"),
              "plain, caf\xc3\xa9, \xe2\x82\xac, \xf0\x9f\x94\x86\n\tend");
    EXPECT_EQ(printable("\xff\xfe"), "\\xff\\xfe");                       // bytes that never start UTF-8
    EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");                       // overlong '/'
    EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");              // a UTF-16 surrogate
    EXPECT_EQ(printable("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");     // beyond U+10FFFF
    EXPECT_EQ(printable("a\xe2\x82"), "a\\xe2\\x82");                     // cut short at the end
    EXPECT_EQ(printable(std::string("\x1b[31m\0", 6)), "\\x1b[31m\\x00"); // terminal escapes, NUL
    EXPECT_EQ(ff::text::quoted("a\nb\xff"), "'a\\x0ab\\xff'");
}
