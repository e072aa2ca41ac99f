#include "core/error.h"
#include "core/file_io.h"

#include <gtest/gtest.h>

#include "test_support.h"

using namespace ff;

TEST(FileIo, AtomicWriteReplacesContentAndLeavesNoTemporary) {
    test::TempDir dir;
    const auto p = dir / "out.txt";
    writeFileAtomic(p, "first");
    writeFileAtomic(p, "second");
    EXPECT_EQ(test::readFile(p), "second");
    std::size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.path())) files += e.is_regular_file();
    EXPECT_EQ(files, 1u);
}

TEST(FileIo, AtomicWriteIntoMissingFolderIsARuntimeError) {
    test::TempDir dir;
    try {
        writeFileAtomic(dir / "missing/out.txt", "x");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Runtime);
    }
}

// A folder written whole: its files and subfolders, an earlier one (marked) replaced, nothing of it
// left beside; a folder of other files, or a file, is not replaceable.
TEST(FileIo, FolderWrittenWholeReplacesOnlyAMarkedOrEmptyFolder) {
    test::TempDir dir;
    const auto out = dir / "project";
    EXPECT_TRUE(replaceableFolder(out, ".mark"));
    writeFolderAtomic(out, {{".mark", ""}, {"a.txt", "one"}, {"sub/deeper/b.txt", "two"}});
    EXPECT_EQ(test::readFile(out / "sub/deeper/b.txt"), "two");
    EXPECT_TRUE(replaceableFolder(out, ".mark"));
    writeFolderAtomic(out, {{".mark", ""}, {"c.txt", "three"}});
    EXPECT_FALSE(std::filesystem::exists(out / "a.txt")); // replaced whole, not merged
    EXPECT_EQ(test::readFile(out / "c.txt"), "three");
    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
    EXPECT_EQ(entries, 1u); // no temporary or old folder left beside it
    std::filesystem::create_directory(dir / "empty");
    EXPECT_TRUE(replaceableFolder(dir / "empty", ".mark"));
    std::filesystem::create_directory(dir / "theirs");
    writeFileAtomic(dir / "theirs/notes.txt", "mine");
    EXPECT_FALSE(replaceableFolder(dir / "theirs", ".mark"));
    writeFileAtomic(dir / "file", "x");
    EXPECT_FALSE(replaceableFolder(dir / "file", ".mark"));
}

TEST(FileIo, ReadChecksExistenceKindAndSizeBeforeReading) {
    test::TempDir dir;
    test::writeFile(dir / "a.txt", "12345");
    EXPECT_EQ(readFileBytes(dir / "a.txt", 5), "12345");
    EXPECT_THROW(readFileBytes(dir / "a.txt", 4), Error);
    EXPECT_THROW(readFileBytes(dir / "nope.txt", 100), Error);
    EXPECT_THROW(readFileBytes(dir.path(), 100), Error);
}

TEST(FileIo, SamePathSeesThroughDotSegments) {
    test::TempDir dir;
    test::writeFile(dir / "a.txt", "x");
    EXPECT_TRUE(samePath(dir / "a.txt", dir.path() / "." / "a.txt"));
    EXPECT_FALSE(samePath(dir / "a.txt", dir / "b.txt"));
}

TEST(FileIo, HashIsFnv1a64) {
    // FNV-1a 64 reference values: empty input is the offset basis; "a" from the published test vectors.
    EXPECT_EQ(hashHex(""), "cbf29ce484222325");
    EXPECT_EQ(hashHex("a"), "af63dc4c8601ec8c");
}
