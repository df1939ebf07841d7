// The atomic writer every command uses (src/cnccomp/io/text_util.*), as `correct` and `poses` rely on it: targets that
// are not regular files are refused before any work (a device node such as /dev/null must stay a device even for root;
// a FIFO, a folder), temporary files are created exclusively with unpredictable names beside the target (a symlink
// planted at a predictable name is not followed), a failure leaves nothing behind, a link is followed to its target.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;

mode_t modeOf(const std::string& p) {
    struct stat st {};
    return ::lstat(p.c_str(), &st) == 0 ? st.st_mode : 0;
}

size_t entries(const fs::path& dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

TEST(PostprocOutputFile, DeviceNodeStaysADevice) {
    // /dev/null itself is only checked (read-only); the write is tried on a copy of the node in a scratch folder.
    EXPECT_THROW(checkOutputPath("/dev/null"), InputError);
    EXPECT_TRUE(S_ISCHR(modeOf("/dev/null")));
    test::ScratchDir dir("pp-out-dev");
    const std::string node = dir.file("null");
    if (::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0)
        GTEST_SKIP() << "cannot create a device node here (needs root): the device case is covered by the FIFO test";
    bool wrote = false;
    try {
        writeFileAtomically(node, [&](std::ostream& o) { wrote = true, o << "data\n"; });
        FAIL() << "a device node must be refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("character device"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(wrote) << "refused before any work";
    EXPECT_TRUE(S_ISCHR(modeOf(node))) << "the node was replaced";
    EXPECT_EQ(entries(dir.path), 1u) << "no temporary file left";
}

TEST(PostprocOutputFile, FifoAndFolderAreRefusedBeforeAnyWork) {
    test::ScratchDir dir("pp-out-fifo");
    const std::string fifo = dir.file("pipe");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    bool wrote = false;
    EXPECT_THROW(writeFileAtomically(fifo, [&](std::ostream&) { wrote = true; }), InputError);
    EXPECT_FALSE(wrote);
    EXPECT_TRUE(S_ISFIFO(modeOf(fifo)));
    fs::create_directory(dir.file("folder"));
    try {
        writeFileAtomically(dir.file("folder"), [&](std::ostream&) { wrote = true; });
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("a directory"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(wrote);
    EXPECT_THROW(checkOutputPath(dir.file("no-such-folder/out.nc")), InputError);
    EXPECT_EQ(entries(dir.path), 2u);
}

TEST(PostprocOutputFile, PlantedSymlinkAtAPredictableTemporaryNameIsNotFollowed) {
    test::ScratchDir dir("pp-out-symlink");
    const std::string victim = dir.file("victim.txt");
    test::writeText(victim, "precious\n");
    const std::string target = dir.file("out.nc");
    // Every name the old writer could have used (".out.nc.tmp<pid>") and a few plain guesses point at the victim.
    for (const std::string& name : {".out.nc.tmp" + std::to_string(::getpid()), std::string(".out.nc.tmp"),
                                    std::string("out.nc.tmp"), "out.nc.tmp" + std::to_string(::getpid())})
        fs::create_symlink(victim, dir.file(name));
    writeFileAtomically(target, [](std::ostream& o) { o << "G0 X1\n"; });
    EXPECT_EQ(test::readText(victim), "precious\n");
    EXPECT_EQ(test::readText(target), "G0 X1\n");
    EXPECT_FALSE(S_ISLNK(modeOf(target)));
}

TEST(PostprocOutputFile, TemporaryFilesAreExclusiveUnpredictableAndBesideTheTarget) {
    test::ScratchDir dir("pp-out-tmp");
    const std::string target = dir.file("out.nc");
    AtomicFile a(target), b(target);
    EXPECT_NE(a.temporaryPath(), b.temporaryPath());
    EXPECT_EQ(fs::path(a.temporaryPath()).parent_path(), dir.path);
    EXPECT_EQ(a.temporaryPath().find(std::to_string(::getpid())), std::string::npos) << a.temporaryPath();
    EXPECT_TRUE(S_ISREG(modeOf(a.temporaryPath())));
    // Exclusive: creating the same name again fails.
    EXPECT_LT(::open(a.temporaryPath().c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600), 0);
    a.stream() << "first\n";
    a.commit();
    EXPECT_EQ(test::readText(target), "first\n");
    EXPECT_FALSE(fs::exists(a.temporaryPath()));
    // b is dropped without commit: its temporary file goes, the committed target stays.
}

TEST(PostprocOutputFile, FailureLeavesNoHalfFileAndAnExistingTargetKeepsItsModeAndLinks) {
    test::ScratchDir dir("pp-out-fail");
    const std::string target = dir.file("out.nc");
    test::writeText(target, "old\n");
    ::chmod(target.c_str(), 0640);
    EXPECT_THROW(writeFileAtomically(target, [](std::ostream& o) {
                     o << "half";
                     throw std::runtime_error("interrupted");
                 }),
                 std::runtime_error);
    EXPECT_EQ(test::readText(target), "old\n");
    EXPECT_EQ(entries(dir.path), 1u);
    writeFileAtomically(target, [](std::ostream& o) { o << "new\n"; });
    EXPECT_EQ(modeOf(target) & 0777, 0640u);
    // A symbolic link as output: the file it names is replaced, the link stays a link.
    fs::create_directory(dir.file("real"));
    test::writeText(dir.file("real/data.nc"), "x\n");
    fs::create_symlink("real/data.nc", dir.file("link.nc"));
    writeFileAtomically(dir.file("link.nc"), [](std::ostream& o) { o << "through the link\n"; });
    EXPECT_TRUE(S_ISLNK(modeOf(dir.file("link.nc"))));
    EXPECT_EQ(test::readText(dir.file("real/data.nc")), "through the link\n");
}

TEST(PostprocOutputFile, CommandsRefuseAFolderOrDeviceAsOutputBeforeReadingTheirInputs) {
    test::ScratchDir dir("pp-out-cli");
    // The machine file is malformed: a command that did work before checking --out would complain about it first.
    test::writeText(dir.file("bad.xml"), "<machine");
    test::writeText(dir.file("p.nc"), "G0 X1\n");
    test::writeText(dir.file("d.csv"), "name,alias,value,unit\n");
    fs::create_directory(dir.file("outdir"));
    auto r = test::runCli("correct --machine " + dir.file("bad.xml") + " --deviations " + dir.file("d.csv") + " --in " +
                          dir.file("p.nc") + " --out " + dir.file("outdir"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("outdir: the output is a directory"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("bad.xml"), std::string::npos) << r.out;
    r = test::runCli("correct --machine " + dir.file("bad.xml") + " --deviations " + dir.file("d.csv") + " --in " +
                     dir.file("p.nc") + " --out " + dir.file("o.nc") + " --report " + dir.file("outdir"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("a directory"), std::string::npos) << r.out;
    r = test::runCli("poses --in " + dir.file("p.nc") + " --out " + dir.file("outdir"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("a directory"), std::string::npos) << r.out;
    EXPECT_EQ(entries(dir.path), 4u);
}

}  // namespace
}  // namespace cnccomp
