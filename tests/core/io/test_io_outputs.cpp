// Every command writes all of its outputs or none (io/output_set.hpp), on a full disk and on a read-only one, with a
// message naming the folder (emit left two files on a full disk and printed a raw filesystem error on a
// read-only one; testprog left an empty folder). The disks are small tmpfs mounts (root only; skipped, saying why,
// where mounting is not permitted).
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace cnccomp {
namespace {

namespace fs = std::filesystem;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

/// A tmpfs of `kb` KiB at `dir`, mounted with `options`, unmounted at destruction.
struct SmallDisk {
    std::string dir, why;
    bool mounted = false;
    SmallDisk(const std::string& d, int kb, bool readOnly) : dir(d) {
        fs::create_directories(dir);
        const std::string opts = "size=" + std::to_string(kb) + "k";
        if (::mount("tmpfs", dir.c_str(), "tmpfs", readOnly ? MS_RDONLY : 0, opts.c_str()) == 0) mounted = true;
        else why = std::string("mounting a tmpfs is not permitted here: ") + std::strerror(errno);
    }
    ~SmallDisk() {
        if (mounted) ::umount(dir.c_str());
    }
};

size_t entries(const std::string& dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

/// Fills the disk at `dir` but for `leaveKb` KiB.
void fill(const std::string& dir, int totalKb, int leaveKb) {
    std::ofstream f(dir + "/filler", std::ios::binary);
    const std::string block(1024, 'x');
    for (int i = 0; i < totalKb - leaveKb; ++i) f << block;
}

TEST(OutputsAllOrNone, EmitOnAFullDiskLeavesNothing) {
    test::ScratchDir scratch("io-out-emit-full");
    SmallDisk disk(scratch.file("disk"), 256, false);
    if (!disk.mounted) GTEST_SKIP() << disk.why;
    fill(disk.dir, 256, 12);
    const size_t before = entries(disk.dir);
    const auto r = test::runCli("emit --controller generic --machine " + kMachine + " --deviations " + kTruth + " --out " +
                                disk.dir + "/comp");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find(disk.dir + "/comp"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("No space left"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(disk.dir + "/comp")) << "a folder or files were left";
    EXPECT_EQ(entries(disk.dir), before);
}

TEST(OutputsAllOrNone, TestprogOnAFullDiskLeavesNoFolder) {
    test::ScratchDir scratch("io-out-testprog-full");
    SmallDisk disk(scratch.file("disk"), 256, false);
    if (!disk.mounted) GTEST_SKIP() << disk.why;
    fill(disk.dir, 256, 12);
    const auto r = test::runCli("testprog --machine " + kMachine + " --plan " +
                                test::sourcePath("samples/plans/multitasking-six-circles.xml") + " --out " + disk.dir + "/progs");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find(disk.dir + "/progs"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(disk.dir + "/progs")) << "an empty folder was left";
}

TEST(OutputsAllOrNone, EmitOnAReadOnlyDiskNamesTheFolder) {
    test::ScratchDir scratch("io-out-emit-ro");
    SmallDisk disk(scratch.file("disk"), 64, true);
    if (!disk.mounted) GTEST_SKIP() << disk.why;
    const auto r = test::runCli("emit --controller generic --machine " + kMachine + " --deviations " + kTruth + " --out " +
                                disk.dir + "/comp");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find(disk.dir + "/comp"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Read-only file system"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("filesystem error"), std::string::npos) << r.out;
    EXPECT_EQ(entries(disk.dir), 0u);
}

}  // namespace
}  // namespace cnccomp
