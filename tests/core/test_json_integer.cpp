#include "core/json_integer.h"

#include <gtest/gtest.h>

#include <cstdint>

using ff::jsonInteger;
using ff::jsonIntegers;
using nlohmann::json;

// The bounds are the C++ types' own: int32 [-2^31, 2^31 - 1], uint32 [0, 2^32 - 1], uint64 [0, 2^64 - 1].
TEST(JsonInteger, AcceptsIntegersWithinTheTypesRange) {
    EXPECT_EQ(jsonInteger<int>(json::parse("-2147483648")), -2147483647 - 1);
    EXPECT_EQ(jsonInteger<int>(json::parse("2147483647")), 2147483647);
    EXPECT_EQ(jsonInteger<std::uint32_t>(json::parse("4294967295")), 4294967295u);
    EXPECT_EQ(jsonInteger<std::uint64_t>(json::parse("18446744073709551615")), UINT64_MAX);
    // An integral float is the integer a hand-edited or another tool's file means.
    EXPECT_EQ(jsonInteger<int>(json::parse("6.0")), 6);
    EXPECT_EQ(jsonInteger<std::size_t>(json::parse("1e3")), 1000u);
    EXPECT_EQ(jsonIntegers<std::size_t>(json::parse("[3, 7]")), (std::vector<std::size_t>{3, 7}));
}

TEST(JsonInteger, RefusesWhatGetWouldConvertWithUndefinedBehaviourOrWrapping) {
    for (const char* text :
         {"1e308", "-1e308", "2147483648", "-2147483649", "2147483648.0", "2.5", "\"6\"", "true", "null", "[1]"})
        EXPECT_THROW(jsonInteger<int>(json::parse(text)), json::type_error) << text;
    for (const char* text : {"-1", "-0.5", "4294967296", "1e10"})
        EXPECT_THROW(jsonInteger<std::uint32_t>(json::parse(text)), json::type_error) << text;
    // 2^64 is the first double past uint64's range.
    EXPECT_THROW(jsonInteger<std::uint64_t>(json::parse("18446744073709551616.0")), json::type_error);
    EXPECT_THROW(jsonIntegers<std::size_t>(json::parse("[1, 1e308]")), json::type_error);
    EXPECT_THROW(jsonIntegers<std::size_t>(json::parse("{\"a\": 1}")), json::type_error);
}
