// Component errors (error motions) of the C axis from the DBB5 profiles of the B/C plan (Ibaraki et al., 1st report,
// section 4.2.2): round trips from known component tables — in the bed frame (the paper's definition, compared with
// R(θ)·t(θ) of the truth at every sample angle) and converted back to the model's tables — with the location errors
// identified from the same runs; seeded noise against a stated bound; what the runs cannot see is left alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include <Eigen/LU>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_component_errors.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_dbb5_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& bc() { return test::tableTableBc(); }
const MeasurementPlan& plan() { return test::dbb5PlanBc(); }

/// Value of table `name` at angle q (rad), as the model interpolates it.
double table(const DeviationSet& s, const std::string& name, double q) {
    const DeviationDef& d = s.machine().deviations[static_cast<size_t>(s.require(name))];
    return d.basis.evaluate(q, s.values.data() + d.offset, true);
}

Vec3 bedFrame(const DeviationSet& s, const char* x, const char* y, const char* z, double q) {
    return Eigen::AngleAxisd(q, Vec3::UnitZ()) * Vec3(table(s, x, q), table(s, y, q), z ? table(s, z, q) : 0.0);
}

/// Adds c_k(ν) = R(−ν)·k − k (k = X, Y) to the node values of tables (x, y) so that the bed-frame mean of R(θ)·t(θ)
/// over the sample angles is zero: the axis average line carries the mean (ISO 230-7), the profiles do not. The
/// correction is zero at 0° and linear in k; the 2 × 2 system is solved with the model's own interpolation.
void gauge(DeviationSet& s, const char* x, const char* y, const std::vector<double>& samplesDeg) {
    const auto mean = [&](const DeviationSet& t) {
        Eigen::Vector2d sum = Eigen::Vector2d::Zero();
        for (double a : samplesDeg) sum += bedFrame(t, x, y, nullptr, a * kDeg).head<2>();
        return Eigen::Vector2d(sum / static_cast<double>(samplesDeg.size()));
    };
    const DeviationDef& dx = s.machine().deviations[static_cast<size_t>(s.require(x))];
    const DeviationDef& dy = s.machine().deviations[static_cast<size_t>(s.require(y))];
    const auto correction = [&](const Vec3& k, DeviationSet& t) {
        for (size_t i = 0; i < dx.basis.nodes.size(); ++i) {
            const Vec3 c = Eigen::AngleAxisd(-dx.basis.nodes[i], Vec3::UnitZ()) * k - k;
            t.values[dx.offset + static_cast<int>(i)] += c.x();
            t.values[dy.offset + static_cast<int>(i)] += c.y();
        }
    };
    Eigen::Matrix2d M;
    for (int j = 0; j < 2; ++j) {
        DeviationSet unit(s.machine());
        correction(Vec3::Unit(j), unit);
        M.col(j) = mean(unit);
    }
    const Eigen::Vector2d kappa = M.fullPivLu().solve(-mean(s));
    correction(Vec3(kappa.x(), kappa.y(), 0), s);
}

/// Location truth of the sample plus component tables of C (twelve nodes, zero at 0°), in the method's gauge.
DeviationSet truthWithComponents() {
    DeviationSet s = test::dbb5TruthBc();
    const double tx[12] = {0, 1.2, 2.0, 1.1, -0.5, -1.8, -2.2, -1.0, 0.4, 1.5, 0.9, 0.3};
    const double ty[12] = {0, -0.7, 0.3, 1.6, 2.1, 0.8, -0.6, -1.9, -1.2, 0.2, 0.5, -0.4};
    const double tz[12] = {0, 0.5, 0.9, 0.4, -0.3, -0.8, -0.5, 0.1, 0.6, 0.7, 0.2, -0.2};
    const double ta[12] = {0, 1.5, 2.5, 1.0, -1.0, -2.0, -1.5, 0.5, 1.8, 1.2, -0.5, -0.8};
    const double tb[12] = {0, -1.0, -0.5, 1.5, 2.0, 1.0, -0.5, -2.0, -1.0, 0.5, 1.0, 0.2};
    const double tc[12] = {0, 3.0, 4.0, 2.0, -1.0, -3.0, -4.0, -2.0, 1.0, 3.0, 2.0, 1.0};
    for (const auto& [name, v, unit] : {std::tuple<const char*, const double*, double>{"EXC", tx, kUm}, {"EYC", ty, kUm},
                                        {"EZC", tz, kUm}, {"EAC", ta, kArcsec}, {"EBC", tb, kArcsec}, {"ECC", tc, kArcsec}}) {
        const int d = s.require(name);
        for (int k = 0; k < 12; ++k) s.values[bc().deviations[static_cast<size_t>(d)].offset + k] = v[k] * unit;
        s.present[static_cast<size_t>(d)] = 1;
    }
    const std::vector<double> samples = plan().dbb5Runs[3].anglesDeg();
    gauge(s, "EXC", "EYC", samples);
    gauge(s, "EAC", "EBC", samples);
    return s;
}

std::vector<BallbarTrace> simulate(const DeviationSet& s) {
    std::vector<BallbarTrace> t;
    const Kinematics k(bc(), s);
    for (const Dbb5Run& r : plan().dbb5Runs) t.push_back(simulateDbb5(k, r));
    return t;
}

/// Largest node error of the C tables (µm for EXC EYC EZC, arcsec for EAC EBC).
std::pair<double, double> worstNode(const DeviationSet& got, const DeviationSet& truth) {
    double um = 0, as = 0;
    for (const char* n : {"EXC", "EYC", "EZC", "EAC", "EBC"}) {
        const DeviationDef& d = bc().deviations[static_cast<size_t>(truth.require(n))];
        for (int k = 0; k < d.size(); ++k) {
            const double e = std::abs(got.values[d.offset + k] - truth.values[d.offset + k]);
            (d.isAngle() ? as : um) = std::max(d.isAngle() ? as : um, e / (d.isAngle() ? kArcsec : kUm));
        }
    }
    return {um, as};
}

TEST(Dbb5ComponentErrors, ProfilesAndTablesRoundTrip) {
    const MachineModel& m = bc();
    const DeviationSet truth = truthWithComponents();
    const std::vector<BallbarTrace> traces = simulate(truth);
    const Dbb5LocationResult loc = dbb5LocationErrors(m, plan().dbb5Runs, traces);
    for (const std::string& n : loc.identified) {
        const bool angle = m.deviations[static_cast<size_t>(m.deviationIndex(n))].isAngle();
        EXPECT_NEAR(loc.deviations.get(n), truth.get(n), 0.002 * (angle ? kArcsec : kUm)) << n;  // the gauge holds
    }
    const Dbb5ComponentProfile p = dbb5ComponentProfile(m, plan().dbb5Runs, traces, loc.deviations, "C");
    EXPECT_TRUE(p.tilts);
    EXPECT_TRUE(p.axial);
    EXPECT_EQ(p.reference, 0.0);
    EXPECT_EQ(p.runs, (std::vector<std::string>{"C-X-low", "C-Y-low", "C-X-high", "C-Y-high", "C-Z"}));
    ASSERT_EQ(p.angleDeg.size(), 72u);
    // The paper's definition, bed frame, every sample angle: δ(θ) = R(θ)·t(θ), ε(θ) = R(θ)·ω(θ) of the truth.
    double um = 0, as = 0;
    for (size_t i = 0; i < p.angleDeg.size(); ++i) {
        const double q = p.angleDeg[i] * kDeg;
        um = std::max(um, (p.translation[i] - bedFrame(truth, "EXC", "EYC", "EZC", q)).norm() / kUm);
        const Vec3 tilt = bedFrame(truth, "EAC", "EBC", nullptr, q);
        as = std::max(as, (p.tilt[i].head<2>() - tilt.head<2>()).norm() / kArcsec);
    }
    std::printf("[ dbb5 components ] bed-frame profiles over 72 angles: %.4f um, %.4f arcsec\n", um, as);
    EXPECT_LT(um, 0.005);
    EXPECT_LT(as, 0.005);
    // Converted to the model's tables (turning frame) at their nodes.
    const DeviationSet tables = dbb5ComponentTables(m, p, loc.deviations);
    const auto [tum, tas] = worstNode(tables, truth);
    std::printf("[ dbb5 components ] tables EXC EYC EZC EAC EBC: %.4f um, %.4f arcsec\n", tum, tas);
    EXPECT_LT(tum, 0.005);
    EXPECT_LT(tas, 0.005);
    for (const char* n : {"EXC", "EYC", "EZC", "EAC", "EBC"}) EXPECT_TRUE(tables.present[static_cast<size_t>(m.deviationIndex(n))]) << n;
    // The angular positioning error does not move a ball on the axis: ECC is neither seen nor written.
    EXPECT_FALSE(tables.present[static_cast<size_t>(m.deviationIndex("ECC"))]);
    for (int k = 0; k < 12; ++k) EXPECT_EQ(tables.values[m.deviations[static_cast<size_t>(m.deviationIndex("ECC"))].offset + k], 0.0);
}

TEST(Dbb5ComponentErrors, OneHeightGivesTranslationsOnly) {
    const MachineModel& m = bc();
    DeviationSet truth = truthWithComponents();
    for (const char* n : {"EAC", "EBC"}) {  // no tilt motions: one height suffices for the translations
        const DeviationDef& d = m.deviations[static_cast<size_t>(m.deviationIndex(n))];
        for (int k = 0; k < d.size(); ++k) truth.values[d.offset + k] = 0;
    }
    const std::vector<BallbarTrace> all = simulate(truth);
    std::vector<Dbb5Run> runs;
    std::vector<BallbarTrace> traces;
    for (size_t i = 0; i < plan().dbb5Runs.size(); ++i)
        if (plan().dbb5Runs[i].name.find("-high") == std::string::npos) {
            runs.push_back(plan().dbb5Runs[i]);
            traces.push_back(all[i]);
        }
    // The location errors of the truth stand in for the identified ones (the C line needs both heights).
    const DeviationSet location = test::dbb5TruthBc();
    const Dbb5ComponentProfile p = dbb5ComponentProfile(m, runs, traces, location, "C");
    EXPECT_FALSE(p.tilts);
    EXPECT_EQ(p.reference, 50.0);
    DeviationSet base(m);
    const DeviationSet tables = dbb5ComponentTables(m, p, base);
    EXPECT_FALSE(tables.present[static_cast<size_t>(m.deviationIndex("EAC"))]);
    const auto [um, as] = worstNode(tables, truth);
    EXPECT_LT(um, 0.005);
    EXPECT_EQ(as, 0.0);
}

TEST(Dbb5ComponentErrors, NoisyProfilesStayWithinTheStatedBound) {
    // σ = 0.1 µm on every sample. A translation node at the axis origin is extrapolated from one sample of each of
    // the runs at 50 and 150 mm: 1.5·D(50) − 0.5·D(150), σ·√2.5 ≈ 0.16 µm (bound 5 of them, 0.8 µm, over 36 node
    // values); a tilt node is the difference of two runs 100 mm apart: σ·√2/100 mm ≈ 0.3 arcsec (bound 1.5 arcsec).
    const MachineModel& m = bc();
    const DeviationSet truth = truthWithComponents();
    std::vector<BallbarTrace> traces = simulate(truth);
    std::mt19937_64 rng(424242);
    std::normal_distribution<double> noise(0.0, 0.1 * kUm);
    for (BallbarTrace& t : traces)
        for (double& v : t.dL) v += noise(rng);
    const Dbb5LocationResult loc = dbb5LocationErrors(m, plan().dbb5Runs, traces);
    const DeviationSet tables =
        dbb5ComponentTables(m, dbb5ComponentProfile(m, plan().dbb5Runs, traces, loc.deviations, "C"), loc.deviations);
    const auto [um, as] = worstNode(tables, truth);
    std::printf("[ dbb5 components ] noise 0.1 um: worst node %.3f um, %.3f arcsec\n", um, as);
    EXPECT_LT(um, 0.8);
    EXPECT_LT(as, 1.5);
}

TEST(Dbb5ComponentErrors, CommandLineEndToEnd) {
    // simulate-runs with the truth (location + C tables) → dbb5 --components → the deviation file holds both; the
    // profile CSV has one row per sample angle. Outputs never overwrite inputs.
    test::ScratchDir dir("dbb5-components-cli");
    const DeviationSet truth = truthWithComponents();
    writeDeviationCsv(dir.file("truth.csv"), truth);
    const std::string m = test::sourcePath("samples/machines/table-table-bc.xml");
    const std::string p = test::sourcePath("samples/plans/dbb5-table-table-bc.xml");
    auto r = test::runCli("simulate --machine " + m + " --plan " + p + " --deviations " + dir.file("truth.csv") +
                          " --out " + dir.file("traces"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("identify --method formulas --machine " + m + " --plan " + p + " --traces " + dir.file("traces") + " --out " +
                     dir.file("d.csv") + " --components --profile-out " + dir.file("profile.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("XYC test C-XY"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("cone frustum cone"), std::string::npos) << r.out;
    const DeviationSet got = readDeviationCsv(dir.file("d.csv"), bc());
    const auto [um, as] = worstNode(got, truth);
    EXPECT_LT(um, 0.005);
    EXPECT_LT(as, 0.005);
    EXPECT_NEAR(got.get("EX0C"), truth.get("EX0C"), 0.002 * kUm);
    const std::string profile = test::readText(dir.file("profile.csv"));
    EXPECT_EQ(std::count(profile.begin(), profile.end(), '\n'), 73);
    EXPECT_EQ(profile.rfind("angle_deg,dx_um,dy_um,dz_um,ex_arcsec,ey_arcsec,ez_arcsec\n", 0), 0u);
    r = test::runCli("identify --method formulas --machine " + m + " --plan " + p + " --traces " + dir.file("traces") + " --out " +
                     dir.file("d2.csv") + " --components --profile-out " + p);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    r = test::runCli("identify --method formulas --machine " + m + " --plan " + p + " --traces " + dir.file("traces") + " --out " +
                     dir.file("d3.csv") + " --profile-out " + dir.file("p3.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("--profile-out needs --components"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("d3.csv")));
}

TEST(Dbb5ComponentErrors, MissingOrMismatchedRunsAreNamed) {
    const MachineModel& m = bc();
    const DeviationSet zero(m);
    const std::vector<BallbarTrace> traces = simulate(zero);
    std::vector<Dbb5Run> runs;
    std::vector<BallbarTrace> t;
    for (size_t i = 0; i < plan().dbb5Runs.size(); ++i)
        if (plan().dbb5Runs[i].name.rfind("C-Y", 0) != 0) {
            runs.push_back(plan().dbb5Runs[i]);
            t.push_back(traces[i]);
        }
    try {
        dbb5ComponentProfile(m, runs, t, zero, "C");
        ADD_FAILURE() << "expected a ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("the bar along Y"), std::string::npos) << e.what();
    }
    std::vector<Dbb5Run> coarse = plan().dbb5Runs;
    coarse[4].stepDeg = 10;  // C-Y-low sampled every 10°
    std::vector<BallbarTrace> t2 = traces;
    t2[4] = simulateDbb5(Kinematics(m), coarse[4]);
    try {
        dbb5ComponentProfile(m, coarse, t2, zero, "C");
        ADD_FAILURE() << "expected a ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("'C-Y-low' has other sample angles"), std::string::npos) << e.what();
    }
    EXPECT_THROW(dbb5ComponentProfile(m, plan().dbb5Runs, traces, zero, "X"), ModelError);
}

}  // namespace
}  // namespace cnccomp
