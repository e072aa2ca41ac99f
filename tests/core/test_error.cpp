#include "core/error.h"

#include <gtest/gtest.h>

using namespace ff;

TEST(Error, MessageCarriesFileLineColumn) {
    const Error e(ErrorKind::Input, {"x.lens", 12, 8}, "expected a number");
    EXPECT_STREQ(e.what(), "x.lens:12:8: expected a number");
    EXPECT_EQ(e.message(), "expected a number");
    EXPECT_EQ(Error(ErrorKind::Input, {"x.lens", 3, 0}, "m").what(), std::string("x.lens:3: m"));
    EXPECT_EQ(Error(ErrorKind::Runtime, "m").what(), std::string("m"));
}

TEST(Error, ExitCodes) {
    EXPECT_EQ(exitCodeFor(ErrorKind::Input), 2);
    EXPECT_EQ(exitCodeFor(ErrorKind::Usage), 2);
    EXPECT_EQ(exitCodeFor(ErrorKind::Runtime), 1);
}
