// README "Your own machine": every `cnccomp …` command of the walk-through, as written there, runs in a scratch folder
// (with the repository's samples/ beside it) and succeeds; the last (verify) predicts what the README says, and the
// laser step's set holds the circles' squareness and the laser's EXX. Oracle: the README's own text (a walk-through
// that drifts from the program fails here).
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/geometry.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

std::vector<std::string> walkThroughCommands() {
    const std::string readme = test::readText(test::sourcePath("README.md"));
    const size_t from = readme.find("## Your own machine");
    const size_t to = readme.find("\n## ", from + 1);
    const std::string section = readme.substr(from, to - from);
    std::vector<std::string> out;
    const std::regex command("`(cnccomp [^`]*)`");
    for (auto it = std::sregex_iterator(section.begin(), section.end(), command); it != std::sregex_iterator(); ++it)
        out.push_back((*it)[1].str());
    return out;
}

TEST(OwnMachineReadme, EveryCommandOfTheWalkThroughRuns) {
    const std::vector<std::string> commands = walkThroughCommands();
    ASSERT_GE(commands.size(), 7u);
    const test::ScratchDir dir("own-machine");
    std::filesystem::create_directory_symlink(test::sourcePath("samples"), dir.path / "samples");
    std::string last;
    for (const std::string& c : commands) {
        const test::CliResult r = test::runCommand(fmt::format("cd '{}' && '{}' {}", dir.path.string(), test::cliPath(), c.substr(8)));
        ASSERT_EQ(r.exitCode, 0) << c << "\n" << r.out;
        last = r.out;
    }
    // Before: the identified machine with the laser's BX as lost motion (verify simulates it); after: BACKLASH takes it out.
    EXPECT_NE(last.find("residual (largest span after compensation): 0.002 um (before: 5.320 um)"), std::string::npos) << last;
    const MachineModel m = readMachineXml(test::sourcePath("samples/machines/mill-3axis.xml"));
    const DeviationSet set = readDeviationCsv(dir.file("own/machine.csv"), m);
    EXPECT_NEAR(set.get("EC0Y") / kArcsec, 5.0, 0.5);  // the circles' squareness (0.5 µm noise)
    EXPECT_NEAR(set.values[m.deviations[static_cast<size_t>(m.deviationIndex("EXX"))].offset] / kUm, 0.02014, 1e-5);  // the laser's
    EXPECT_TRUE(std::filesystem::exists(dir.file("own/laser/X.comp")));
    EXPECT_TRUE(std::filesystem::exists(dir.file("own/emit-linuxcnc/cnccomp_kins.comp")));
}

}  // namespace
}  // namespace cnccomp
