// The closed loop of issue 9 on every sample machine: simulate the plan with a truth set → identify (least squares) →
// emit with each of the six backends → verify through the emitted files (read back by Backend::apply), through
// corrected test programs, and with measurement noise. Oracle: the simulation on the true machine (the truth set is
// known), with the instrument readings analysed like measured ones.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <sstream>

#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/rtest_observation.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/verify.hpp"
#include "cnccomp/verify_sources.hpp"
#include "postproc/processor.hpp"
#include "postproc/testprog/test_program.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

struct Case {
    const char* machine;
    const char* plan;
    const char* truth;
};
constexpr Case kCases[] = {
    {"multitasking", "multitasking-six-circles.xml", "multitasking-truth.csv"},  // seed 000, six ball-bar runs
    {"table-table-ac", "table-table-ac-rtest.xml", "table-table-ac-truth.csv"},  // seed 001, R-test, 11 errors
    {"tilting-head-b", "tilting-head-b-patterns.xml", "tilting-head-b-truth.csv"},  // head patterns (absolute bar, two tool lengths), B tables
};

struct Loop {
    MachineModel machine;
    MeasurementPlan plan;
    std::unique_ptr<DeviationSet> truth;
};

Loop load(const Case& c) {
    Loop l;
    l.machine = readMachineXml(test::sourcePath(std::string("samples/machines/") + c.machine + ".xml"));
    l.plan = readPlanXml(test::sourcePath(std::string("samples/plans/") + c.plan));
    for (BallbarRun& r : l.plan.runs) r.stepDeg = 5;  // fewer samples: the suite stays fast, the loop is the same
    l.truth = std::make_unique<DeviationSet>(readDeviationCsv(test::sourcePath(std::string("samples/deviations/") + c.truth), l.machine));
    return l;
}

/// simulate → identify by least squares (the engine of `cnccomp identify`, `rtest --lsq`, `tilting-head --lsq`),
/// with Gaussian noise of σ = noiseUm on every reading.
DeviationSet simulateAndIdentify(const Loop& l, double noiseUm, unsigned seed = 7) {
    const MachineModel& m = l.machine;
    const Kinematics k(m, *l.truth);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, noiseUm * kUm);
    const auto noisy = [&](BallbarTrace t) {
        if (noiseUm > 0)
            for (double& v : t.dL) v += noise(rng);
        return t;
    };
    IdentifyOptions io;
    for (size_t i = 0; i < m.deviations.size(); ++i)
        if (l.truth->present[i]) io.deviations.push_back(static_cast<int>(i));
    if (!l.plan.runs.empty()) {
        std::vector<BallbarTrace> traces;
        for (const BallbarRun& r : l.plan.runs) traces.push_back(noisy(simulateRun(k, r)));
        return identify(m, ballbarObservations(m, l.plan.runs, traces), io).deviations;
    }
    if (!l.plan.rtestRuns.empty()) {
        std::vector<RtestTrace> traces;
        for (const RtestRun& r : l.plan.rtestRuns) {
            traces.push_back(simulateRtest(k, r));
            if (noiseUm > 0)
                for (Vec3& d : traces.back().d) d += Vec3(noise(rng), noise(rng), noise(rng));
        }
        return identify(m, rtestObservations(m, l.plan.rtestRuns, traces), io).deviations;
    }
    std::vector<BallbarTrace> traces;
    for (const BallbarRun& r : l.plan.absoluteRuns) traces.push_back(noisy(simulateAbsoluteRun(k, r)));
    return tiltingHeadLeastSquares(m, l.plan.absoluteRuns, traces).deviations;
}

/// The set with every deviation not named in `keep` set to zero.
DeviationSet restricted(const DeviationSet& d, const std::set<std::string>& keep) {
    DeviationSet out = d;
    const MachineModel& m = d.machine();
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& def = m.deviations[i];
        if (keep.count(def.name)) continue;
        out.values.segment(def.offset, def.size()).setZero();
    }
    return out;
}

VerifyOptions fastOptions() {
    VerifyOptions o;
    o.volumetricPerAxis = 3;
    return o;
}

/// Combinations whose apply model leaves more than 0.1 µm of what the backend claims, as measured on this branch
/// (largest ΔL span after, µm). verify finds them: that is its job. The loop holds them to these figures (a backend that
/// gets worse fails) and says when one has come below 0.1 µm (then delete its line). The backends' open work:
///  - generic: the map is a multilinear grid at tool length 0 and the orientation is not corrected;
///  - heidenhain-tnc, siemens-840d: tilts about X of the multi-tasking machine's C1, B, Y and C (EA0C1 EA0B EA0Z EA0C)
///    stay (12–24 µm each alone), and the tilting head's component tables leave 10–14 µm;
///  - isg on the table-table machine (0.77 µm), fanuc-30i on the tilting head (3.0 µm).
struct KnownGap {
    std::string_view backend, machine;
    double boundUm;
};
constexpr KnownGap kKnownGaps[] = {
    {"generic", "multitasking", 2.5},      {"heidenhain-tnc", "multitasking", 18.5}, {"siemens-840d", "multitasking", 18.5},
    {"generic", "table-table-ac", 3.8},    {"isg", "table-table-ac", 0.85},          {"fanuc-30i", "tilting-head-b", 3.2},
    {"generic", "tilting-head-b", 0.95},   {"heidenhain-tnc", "tilting-head-b", 11.0}, {"siemens-840d", "tilting-head-b", 14.6},
};
const KnownGap* knownGap(std::string_view backend, std::string_view machine) {
    for (const KnownGap& g : kKnownGaps)
        if (g.backend == backend && g.machine == machine) return &g;
    return nullptr;
}

TEST(VerifyLoop, EmittedFilesLeaveLessThanATenthOfAMicrometreOfWhatEachBackendClaims) {
    for (const Case& c : kCases) {
        const Loop l = load(c);
        const DeviationSet identified = simulateAndIdentify(l, 0.0);
        for (const controllers::Backend* b : controllers::backends()) {
            const std::string where = std::string(c.machine) + " / " + std::string(b->name());
            const controllers::EmitResult full = b->emit({l.machine, identified, "identified.csv", "2024-01-01"});
            std::set<std::string> claimed;
            for (const auto& cov : full.compensated) claimed.insert(cov.deviation);
            // The loop restricted to what the backend claims: truth and identification without the others.
            const DeviationSet truthClaimed = restricted(*l.truth, claimed), idClaimed = restricted(identified, claimed);
            const controllers::EmitResult files = b->emit({l.machine, idClaimed, "identified.csv", "2024-01-01"});
            VerifyCompensation comp;
            comp.kind = VerifyCompensation::Kind::ControllerFiles;
            comp.description = where;
            comp.model = std::shared_ptr<const controllers::AppliedCompensation>(b->apply(l.machine, files.files));
            const VerifyResult r = verify(l.machine, l.plan, truthClaimed, "truth", comp, fastOptions());
            if (claimed.empty()) continue;
            std::cout << "[ residual ] " << where << ": " << r.residual / kUm << " um (before " << r.residualBefore / kUm << " um)\n";
            if (const KnownGap* g = knownGap(b->name(), c.machine)) {
                EXPECT_LT(r.residual, g->boundUm * kUm) << where << ": a known gap got worse";
                if (r.residual < 0.1 * kUm) std::cout << "[ fixed ] " << where << ": below 0.1 um now, remove it from kKnownGaps\n";
                continue;
            }
            EXPECT_LT(r.residual, 0.1 * kUm) << where << ": before " << r.residualBefore / kUm << " um";
            EXPECT_GT(r.residualBefore, 1.0 * kUm) << where;
        }
    }
}

TEST(VerifyLoop, WhatABackendLeavesIsNamedWithItsReason) {
    for (const Case& c : kCases) {
        const Loop l = load(c);
        const DeviationSet identified = simulateAndIdentify(l, 0.0);
        for (const controllers::Backend* b : controllers::backends()) {
            const std::string where = std::string(c.machine) + " / " + std::string(b->name());
            const controllers::EmitResult files = b->emit({l.machine, identified, "identified.csv", "2024-01-01"});
            VerifyCompensation comp;
            comp.kind = VerifyCompensation::Kind::ControllerFiles;
            comp.model = std::shared_ptr<const controllers::AppliedCompensation>(b->apply(l.machine, files.files));
            // Read from the files' own headers, as `cnccomp verify` does with a folder.
            comp.notCompensated = readNotCompensated(files.files);
            ASSERT_EQ(comp.notCompensated.size(), files.notCompensated.size()) << where;
            const VerifyResult r = verify(l.machine, l.plan, *l.truth, "truth", comp, fastOptions());
            ASSERT_EQ(r.remaining.size(), files.notCompensated.size()) << where;
            for (size_t i = 0; i < r.remaining.size(); ++i) {
                // The header's comment syntax may turn parentheses into brackets (Fanuc).
                const auto brackets = [](std::string t) {
                    std::replace(t.begin(), t.end(), '(', '[');
                    std::replace(t.begin(), t.end(), ')', ']');
                    return t;
                };
                EXPECT_EQ(brackets(r.remaining[i].deviation), brackets(files.notCompensated[i].deviation)) << where;
                EXPECT_EQ(brackets(r.remaining[i].reason), brackets(files.notCompensated[i].note)) << where;
                const int d = l.machine.deviationIndex(r.remaining[i].deviation.substr(0, r.remaining[i].deviation.find(' ')));
                if (d >= 0 && l.truth->present[static_cast<size_t>(d)] && l.machine.deviations[static_cast<size_t>(d)].size() == 1) {
                    ASSERT_TRUE(r.remaining[i].valueKnown) << where;
                    const DeviationDef& def = l.machine.deviations[static_cast<size_t>(d)];
                    const double v = l.truth->values[def.offset] / (def.isAngle() ? kArcsec : kUm);
                    EXPECT_NEAR(r.remaining[i].value, v, 1e-9) << where << " " << def.name;
                }
            }
        }
    }
}

TEST(VerifyLoop, CorrectedTestProgramsLeaveLessThanATenthOfAMicrometre) {
    for (const Case& c : kCases) {
        const Loop l = load(c);
        const DeviationSet identified = simulateAndIdentify(l, 0.0);
        // testprog → cnccomp correct (with the run's tool length, as each program's header says) → verify.
        const auto motions = testprog::planMotions(l.machine, l.plan);
        const auto set = testprog::makeTestPrograms(l.machine, l.plan, {});
        VerifyCompensation comp;
        comp.kind = VerifyCompensation::Kind::CorrectedPrograms;
        comp.description = "corrected programs";
        comp.programDialect = pp::Dialect::Rs274ngc;
        for (size_t i = 0; i < motions.size(); ++i) {
            pp::CorrectOptions co;
            co.dialect = pp::Dialect::Rs274ngc;
            co.setup.defaultToolLength = motions[i].toolLength;
            std::istringstream in(set.programs[i].text);
            std::ostringstream out;
            const pp::CorrectSummary s = pp::correctProgram(l.machine, identified, in, out, co);
            EXPECT_EQ(s.unconverged, 0u) << c.machine << " " << motions[i].name;
            EXPECT_GT(s.corrected, 0u);
            comp.programs.push_back({motions[i].name, {set.programs[i].file, out.str()}});
        }
        const VerifyResult r = verify(l.machine, l.plan, *l.truth, "truth", comp, fastOptions());
        EXPECT_LT(r.residual, 0.1 * kUm) << c.machine << ": before " << r.residualBefore / kUm << " um";
        EXPECT_GT(r.residualBefore, 1.0 * kUm) << c.machine;
        EXPECT_FALSE(r.volumetric.available);
    }
}

TEST(VerifyLoop, WithHalfAMicrometreOfNoiseTheResidualStaysBelowThreeSigma) {
    const double sigma = 0.5;
    for (const Case& c : kCases) {
        Loop l = load(c);
        // The tilting head's 87 unknowns (5 tables × 17 nodes, 2 tilts) take the absolute runs sampled every degree
        // (the instrument samples continuously); at the plan's 15° the 102 samples leave 1.8 µm.
        for (BallbarRun& r : l.plan.absoluteRuns) r.stepDeg = 1;
        const DeviationSet identified = simulateAndIdentify(l, sigma, 11);
        VerifyCompensation comp;
        comp.kind = VerifyCompensation::Kind::Deviations;
        comp.model = idealCompensation(l.machine, identified);
        const VerifyResult r = verify(l.machine, l.plan, *l.truth, "truth", comp, fastOptions());
        EXPECT_LT(r.residual, 3 * sigma * kUm) << c.machine << ": before " << r.residualBefore / kUm << " um";
        std::cout << "[ noise 0.5 um ] " << c.machine << ": residual " << r.residual / kUm << " um (before "
                  << r.residualBefore / kUm << " um)\n";
    }
}

}  // namespace
}  // namespace cnccomp
