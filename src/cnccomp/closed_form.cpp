#include "cnccomp/closed_form.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {
namespace {

bool same(double a, double b) { return std::abs(a - b) <= 1e-6 * (1.0 + std::abs(a) + std::abs(b)); }

const EccentricityRow& single(const std::vector<EccentricityRow>& rows, BallbarTest t) {
    const EccentricityRow* found = nullptr;
    for (const auto& r : rows)
        if (r.test == t) {
            if (found)
                throw ModelError(fmt::format("closed form: two {} rows ({} and {}); keep one", testName(t), found->source,
                                             r.source));
            found = &r;
        }
    if (!found) throw ModelError(fmt::format("closed form: the {} measurement is missing", testName(t)));
    return *found;
}

double need(const EccentricityRow& r, int component) {
    const double v = r.e[component];
    if (!std::isfinite(v))
        throw ModelError(fmt::format("closed form: e{} of the {} run ({}) is empty", "xyz"[component], testName(r.test),
                                     r.source));
    return v;
}

}  // namespace

ClosedFormInputs selectClosedFormInputs(const std::vector<EccentricityRow>& rows) {
    ClosedFormInputs in;
    in.bx = single(rows, BallbarTest::BX);
    in.by = single(rows, BallbarTest::BY);
    in.ca = single(rows, BallbarTest::CAxial);
    std::vector<EccentricityRow> cr;
    for (const auto& r : rows)
        if (r.test == BallbarTest::CRadial) cr.push_back(r);
    if (cr.size() != 3)
        throw ModelError(fmt::format("closed form: three C-radial measurements are needed, at (ZC, RB), (ZC', RB) and "
                                     "(ZC', RB''); found {}",
                                     cr.size()));
    // The pair sharing RB is {(ZC,RB), (ZC',RB)}; the third is (ZC',RB''); ZC' is the ZC it shares.
    for (int odd = 0; odd < 3; ++odd) {
        const auto& a = cr[(odd + 1) % 3];
        const auto& b = cr[(odd + 2) % 3];
        const auto& c = cr[odd];
        if (!same(a.RB, b.RB) || same(c.RB, a.RB)) continue;
        if (same(a.ZC, c.ZC) && !same(b.ZC, c.ZC)) {
            in.crZ = a;
            in.cr = b;
        } else if (same(b.ZC, c.ZC) && !same(a.ZC, c.ZC)) {
            in.crZ = b;
            in.cr = a;
        } else {
            continue;
        }
        in.crR = c;
        if (!same(in.bx.RB, in.cr.RB) || !same(in.by.RB, in.cr.RB))
            throw ModelError("closed form: the B-X and B-Y runs must use the RB of the first C-radial run");
        return in;
    }
    throw ModelError(
        "closed form: the three C-radial runs must be at (ZC, RB), (ZC', RB) and (ZC', RB'') with ZC != ZC' and "
        "RB != RB''");
}

namespace {

/// Equations (17)-(28) applied to one selection of rows; returns the 12 values in `d`.
void applyFormulas(const ClosedFormInputs& in, DeviationSet& d) {
    const double RB = in.cr.RB, RB2 = in.crR.RB, ZC = in.cr.ZC, ZC1 = in.crZ.ZC, RC = in.ca.RC;
    if (!(RC > 0)) throw ModelError("closed form: the C-axial run needs RC > 0");
    const double exBX = need(in.bx, 0), ezBX = need(in.bx, 2);
    const double exBY = need(in.by, 0), ezBY = need(in.by, 2);
    const double exCA = need(in.ca, 0), eyCA = need(in.ca, 1);
    const double exCR = need(in.cr, 0), eyCR = need(in.cr, 1);
    const double exCR1 = need(in.crZ, 0), eyCR1 = need(in.crZ, 1);  // ' : at ZC'
    const double exCR2 = need(in.crR, 0), eyCR2 = need(in.crR, 1);  // '': at ZC', RB''
    const double dZ = ZC1 - ZC;
    d.set("gXB", -exBY / RB);                                                   // (17)
    d.set("dzBT", exBX);                                                        // (18)
    d.set("dxCZ", exCR + ezBX - ZC * (exCR1 - exCR) / dZ);                      // (19)
    d.set("bCZ", (exCR1 - exCR) / dZ);                                          // (20)
    d.set("bYZ", (exCR1 - exCR) / dZ - exCA / RC);                              // (21)
    d.set("aCZ", (eyCR - eyCR1) / dZ);                                          // (22)
    d.set("aYZ", (eyCR - eyCR1) / dZ + eyCA / RC);                              // (23)
    d.set("aXB", ezBY / RB - eyCA / RC - (eyCR - eyCR1) / dZ);                  // (24)
    d.set("dxBT", ezBX + RB * (exCR2 - exCR1) / (RB2 - RB));                    // (25)
    d.set("bXB", (exCR1 - exCR2) / (RB - RB2) - (exCR1 - exCR) / dZ + exCA / RC);  // (26)
    d.set("aBT", (eyCR2 - eyCR1) / (RB - RB2) - ezBY / RB);                     // (27)
    d.set("dyCZ", RB * (eyCR1 - eyCR2) / (RB2 - RB) + (ZC1 * eyCR - ZC * eyCR1) / dZ);  // (28)
}

BallbarRun runOf(const EccentricityRow& row, double stepDeg) {
    BallbarRun r;
    r.name = std::string(testName(row.test)) + " (" + row.source + ")";
    r.test = row.test;
    r.LB = row.LB;
    r.RB = row.RB;
    r.RC = row.RC;
    r.ZC = row.ZC;
    r.startDeg = rotatesHead(row.test) ? -180.0 : 0.0;
    r.endDeg = r.startDeg + 360.0;
    r.stepDeg = stepDeg;
    return r;
}

}  // namespace

DeviationSet identifyClosedForm(const MachineModel& machine, const std::vector<EccentricityRow>& rows,
                                const ClosedFormOptions& options) {
    const ClosedFormInputs measured = selectClosedFormInputs(rows);
    DeviationSet d(machine);
    applyFormulas(measured, d);
    for (int pass = 0; pass < options.refinements; ++pass) {
        // Simulate the six runs on the current estimate; the defect goes back through the (linear) formulas.
        const Kinematics k(machine, d);
        ClosedFormInputs defect = measured;
        for (EccentricityRow* row : {&defect.bx, &defect.by, &defect.ca, &defect.cr, &defect.crZ, &defect.crR}) {
            const BallbarRun run = runOf(*row, options.stepDeg);
            const Vec3 sim = traceEccentricity(machine, run, simulateRun(k, run));
            for (int c = 0; c < 3; ++c) row->e[c] = row->e[c] - sim[c];
        }
        DeviationSet step(machine);
        applyFormulas(defect, step);
        d.values += step.values;
    }
    return d;
}

}  // namespace cnccomp
