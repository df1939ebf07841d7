#include "postproc/klartext_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/line_reader.hpp"

namespace cnccomp::pp {
namespace {

std::string upper(std::string_view s) {
    std::string o;
    for (char c : s) o.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    return o;
}

bool isNumberStart(char c) { return c == '+' || c == '-' || c == '.' || std::isdigit(static_cast<unsigned char>(c)); }

/// One parsed word of a path block.
struct AxisWord {
    int axis = -1;
    bool incremental = false;
    double value = 0;  ///< as written (mm/inch or deg)
};

struct PathWords {
    std::vector<AxisWord> axes;
    int dr = 0;                  ///< +1 DR+, −1 DR−, 0 none
    bool rapid = false;          ///< FMAX
    bool machine = false;        ///< M91 / M92
    bool hasR = false;           ///< CR radius
    double radius = 0;
    bool hasPR = false, incPR = false, hasPA = false, incPA = false;
    double pr = 0, pa = 0;
};

class Reader {
public:
    Reader(const AxisLayout& layout, const PosesOptions& o) : L_(layout), o_(o) {
        pos_ = AxisVector::Zero(L_.count);
        shift_ = AxisVector::Zero(L_.count);
        for (int a = 0; a < L_.count; ++a)
            if (L_.rotary[a]) known_ |= 1u << a;  // rotary axes at 0 until programmed
        for (const auto& [letter, value] : o_.setup.assumed) {
            const int a = L_.axis(static_cast<char>(std::toupper(static_cast<unsigned char>(letter))));
            if (a < 0) continue;
            pos_[a] = L_.rotary[a] ? value * kDeg : value;
            known_ |= 1u << a;
        }
        toolAxis_ = L_.axis('Z');
    }

    /// Interprets one logical block (code without comments); appends a CSV row for a motion block.
    void block(const std::string& code, uint64_t line, std::string& row, PosesSummary& s) {
        line_ = line;
        std::vector<std::string> tok;
        {
            size_t i = 0;
            while (i < code.size()) {
                while (i < code.size() && std::isspace(static_cast<unsigned char>(code[i]))) ++i;
                size_t j = i;
                if (j < code.size() && code[j] == '"') {  // quoted tool name
                    ++j;
                    while (j < code.size() && code[j] != '"') ++j;
                    if (j < code.size()) ++j;
                } else {
                    while (j < code.size() && !std::isspace(static_cast<unsigned char>(code[j]))) ++j;
                }
                if (j > i) tok.push_back(code.substr(i, j - i));
                i = j;
            }
        }
        size_t k = 0;
        if (k < tok.size() && std::all_of(tok[k].begin(), tok[k].end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
            ++k;  // block number
        if (k >= tok.size()) return;
        if (ended_) fail("block after END PGM");
        const std::string key = upper(tok[k]);
        const std::vector<std::string> rest(tok.begin() + static_cast<long>(k) + 1, tok.end());
        if (key == "*") return;  // structure block
        if (key == "BEGIN") return begin(rest);
        if (key == "END") {
            if (rest.empty() || upper(rest[0]) != "PGM") fail("expected END PGM");
            ended_ = true;
            return;
        }
        if (key == "BLK") return;  // workpiece blank for the graphics
        if (key == "TOOL") return tool(rest);
        if (key == "STOP") return mOnly(rest);
        if (key == "CYCL") return cycle(rest);
        if (key == "L") return linear(rest, row, s);
        if (key == "CC") return pole(rest);
        if (key == "C" || key == "CR" || key == "CT") return circle(key, rest, row, s);
        if (key == "LP" || key == "CP") return polar(key, rest, row, s);
        if (key.front() == 'M' && key.size() > 1 && std::isdigit(static_cast<unsigned char>(key[1]))) {
            std::vector<std::string> all{tok[k]};
            all.insert(all.end(), rest.begin(), rest.end());
            return mOnly(all);
        }
        if (key == "LBL" || key == "CALL")
            fail(fmt::format("{} (labels, subprogram calls and repeats) is not supported by cnccomp's Klartext reader: "
                             "write the program out without them", key == "LBL" ? "LBL" : "CALL " + (rest.empty() ? "" : upper(rest[0]))));
        if (key.front() == 'Q' || key == "FN")
            fail("Q parameters and FN functions are not supported by cnccomp's Klartext reader");
        fail(fmt::format("'{}' is not supported by cnccomp's Klartext reader (read: L, C, CC, CR, CT, LP, CP, TOOL CALL, "
                         "CYCL DEF 7/9, STOP, M)", tok[k]));
    }

    bool ended() const { return ended_; }

private:
    [[noreturn]] void fail(const std::string& what) const { throw InputError(o_.inputName, static_cast<int>(line_), what); }

    double linScale() const { return inch_ ? 25.4 : 1.0; }
    double unit(int a) const { return L_.rotary[a] ? kDeg : linScale(); }

    void begin(const std::vector<std::string>& rest) {
        if (rest.size() < 2 || upper(rest[0]) != "PGM") fail("expected BEGIN PGM <name> MM|INCH");
        if (rest.size() >= 3) {
            const std::string u = upper(rest[2]);
            if (u == "INCH") inch_ = true;
            else if (u != "MM") fail(fmt::format("unit '{}' after BEGIN PGM: expected MM or INCH", rest[2]));
        }
    }

    double number(std::string_view text, std::string_view what) const {
        if (!text.empty() && (text.front() == 'Q' || text.front() == 'q' ||
                              ((text.front() == '+' || text.front() == '-') && text.size() > 1 && (text[1] == 'Q' || text[1] == 'q'))))
            fail(fmt::format("{}: Q parameters are not supported by cnccomp's Klartext reader", what));
        const auto v = parseNumber(text);
        if (!v || !std::isfinite(*v)) fail(fmt::format("{}: '{}' is not a number", what, text));
        return *v;
    }

    void tool(const std::vector<std::string>& rest) {
        if (rest.empty()) fail("expected TOOL CALL or TOOL DEF");
        const std::string what = upper(rest[0]);
        if (what == "DEF") return;
        if (what != "CALL") fail("expected TOOL CALL or TOOL DEF");
        size_t i = 1;
        int toolNo = -1;
        if (i < rest.size() && !rest[i].empty() && rest[i].front() == '"') {
            ++i;  // tool by name: its length comes from the default tool length
        } else if (i < rest.size() && std::isdigit(static_cast<unsigned char>(rest[i].front()))) {
            toolNo = static_cast<int>(number(rest[i], "TOOL CALL number"));
            ++i;
        }
        double dl = 0;
        for (; i < rest.size(); ++i) {
            const std::string t = upper(rest[i]);
            if (t.size() == 1 && L_.axis(t[0]) >= 0 && !L_.rotary[L_.axis(t[0])]) {
                toolAxis_ = L_.axis(t[0]);
            } else if (t.rfind("DL", 0) == 0) {
                dl = number(t.substr(2), "TOOL CALL DL") * linScale();
            }  // S, F, DR, DR2: no effect on positions
        }
        double length = o_.setup.defaultToolLength;
        if (toolNo == 0) length = 0;
        else if (toolNo > 0)
            if (const auto l = o_.setup.toolLength(toolNo)) length = *l;
        tlo_ = length + dl;
        tangentKnown_ = false;
    }

    void mOnly(const std::vector<std::string>& rest) {
        for (const std::string& t : rest) {
            const std::string u = upper(t);
            if (u.front() != 'M') fail(fmt::format("unexpected '{}' in a block without motion", t));
            const double m = number(u.substr(1), "M function");
            if (m == 99 || m == 89) fail("M99/M89 cycle calls are not supported by cnccomp's Klartext reader");
        }
    }

    void cycle(const std::vector<std::string>& rest) {
        if (rest.empty()) fail("expected CYCL DEF or CYCL CALL");
        const std::string what = upper(rest[0]);
        if (what == "CALL")
            fail("CYCL CALL: machining cycles are not evaluated by cnccomp's Klartext reader (their moves are not known)");
        if (what != "DEF" || rest.size() < 2) fail("expected CYCL DEF <number>");
        const double id = number(rest[1], "cycle number");
        const int cycle = static_cast<int>(std::floor(id + 1e-9));
        const int sub = static_cast<int>(std::lround((id - cycle) * 10));
        if (cycle == 8 || cycle == 10 || cycle == 11 || cycle == 19 || cycle == 26 || cycle == 247)
            fail(fmt::format("cycle {} (coordinate transformation) is not supported by cnccomp's Klartext reader", cycle));
        if (cycle != 7) return;  // dwell (9) and cycle definitions: no motion
        if (sub == 0) {
            shift_.setZero();
            return;
        }
        for (size_t i = 2; i < rest.size(); ++i) {
            const std::string t = upper(rest[i]);
            if (t.front() == '#') fail("cycle 7 with a datum table line is not supported by cnccomp's Klartext reader");
            const bool inc = t.front() == 'I' && t.size() > 2 && L_.axis(t[1]) >= 0 && isNumberStart(t[2]);
            const size_t p = inc ? 1 : 0;
            const int a = L_.axis(t[p]);
            if (a < 0 || t.size() <= p + 1) fail(fmt::format("cycle 7: '{}' is not an axis value", rest[i]));
            const double v = number(t.substr(p + 1), "datum shift") * unit(a);
            shift_[a] = inc ? shift_[a] + v : v;
        }
    }

    PathWords words(const std::vector<std::string>& rest, bool allowPolar, bool allowRadius) const {
        PathWords w;
        for (const std::string& raw : rest) {
            const std::string t = upper(raw);
            if (t == "R0" || t == "RL" || t == "RR" || t == "R") continue;  // radius compensation: positions as programmed
            if (t == "FMAX") {
                w.rapid = true;
                continue;
            }
            if (t == "FAUTO" || t == "FU" || t == "FZ") continue;
            if (t.front() == 'F' && t.size() > 1 && isNumberStart(t[1])) {
                number(t.substr(1), "feed");
                continue;
            }
            if (t == "DR+" || t == "DR-") {
                w.dr = t[2] == '+' ? 1 : -1;
                continue;
            }
            if (t.front() == 'M' && t.size() > 1 && std::isdigit(static_cast<unsigned char>(t[1]))) {
                const double m = number(t.substr(1), "M function");
                if (m == 91 || m == 92) w.machine = true;
                if (m == 99 || m == 89) fail("M99/M89 cycle calls are not supported by cnccomp's Klartext reader");
                continue;
            }
            if (allowRadius && t.front() == 'R' && t.size() > 1 && isNumberStart(t[1])) {
                w.hasR = true;
                w.radius = number(t.substr(1), "radius R");
                continue;
            }
            if (allowPolar) {
                const bool inc = t.front() == 'I';
                const std::string_view b = std::string_view(t).substr(inc ? 1 : 0);
                if (b.size() > 2 && (b.substr(0, 2) == "PR" || b.substr(0, 2) == "PA") && isNumberStart(b[2])) {
                    const double v = number(b.substr(2), b.substr(0, 2));
                    if (b[1] == 'R') w.hasPR = true, w.incPR = inc, w.pr = v;
                    else w.hasPA = true, w.incPA = inc, w.pa = v;
                    continue;
                }
            }
            const bool inc = t.front() == 'I' && t.size() > 2 && L_.axis(t[1]) >= 0;
            const size_t p = inc ? 1 : 0;
            const int a = L_.axis(t[p]);
            if (a >= 0 && t.size() > p + 1) {
                AxisWord aw;
                aw.axis = a;
                aw.incremental = inc;
                aw.value = number(t.substr(p + 1), std::string(1, t[p]));
                w.axes.push_back(aw);
                continue;
            }
            fail(fmt::format("unexpected '{}'", raw));
        }
        return w;
    }

    /// Applies axis words to a target position; returns the mask of axes the words set.
    unsigned apply(const PathWords& w, AxisVector& end, unsigned& endKnown) const {
        unsigned set = 0;
        for (const AxisWord& aw : w.axes) {
            const int a = aw.axis;
            const unsigned bit = 1u << a;
            if (set & bit) fail(fmt::format("axis {} twice in one block", L_.letter[a]));
            set |= bit;
            const double v = aw.value * unit(a);
            if (aw.incremental) {
                end[a] += v;  // unknown stays unknown
            } else {
                end[a] = w.machine ? v : v + shift_[a] + (a == toolAxis_ ? tlo_ : 0.0);
                endKnown |= bit;
            }
        }
        return set;
    }

    void emitRow(const char* motion, const AxisVector& end, unsigned endKnown, std::string& row, PosesSummary& s) {
        const unsigned all = L_.all();
        const bool complete = (endKnown & all) == all;
        if (!complete) motion = "-";
        s.rows++;
        if (complete) s.moves++;
        else s.passedThrough++;
        row.clear();
        fmt::format_to(std::back_inserter(row), "{},{}", line_, motion);
        static constexpr char kColumns[] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
        for (char c : kColumns) {
            const int a = L_.axis(c);
            if (a < 0 || !(endKnown & (1u << a))) {
                row.push_back(',');
                continue;
            }
            const double v = L_.rotary[a] ? end[a] / kDeg : end[a];
            fmt::format_to(std::back_inserter(row), ",{:.6f}", v == 0 ? 0.0 : v);
        }
        row.push_back('\n');
    }

    /// Remembers the end tangent of a straight move (linear axes X Y Z).
    void tangentOfLine(const AxisVector& from, const AxisVector& to, unsigned knownBoth) {
        Vec3 d = Vec3::Zero();
        bool ok = true;
        for (int c = 0; c < 3; ++c) {
            const int a = L_.axis("XYZ"[c]);
            if (a < 0) continue;
            if (!(knownBoth & (1u << a))) ok = false;
            else d[c] = to[a] - from[a];
        }
        if (ok && d.norm() > 1e-12) {
            tangent_ = d.normalized();
            tangentKnown_ = true;
        }
    }

    void linear(const std::vector<std::string>& rest, std::string& row, PosesSummary& s) {
        const PathWords w = words(rest, false, false);
        if (w.dr != 0) fail("DR+/DR- in a straight block");
        AxisVector end = pos_;
        unsigned endKnown = known_;
        const unsigned set = apply(w, end, endKnown);
        if (!set) return;  // L with only M / F words
        tangentOfLine(pos_, end, known_ & endKnown);
        pos_ = end;
        known_ = endKnown;
        emitRow(w.machine ? "G53" : w.rapid ? "G0" : "G1", end, endKnown, row, s);
    }

    /// Orders two linear axes as a right-handed plane (X,Y), (Y,Z), (Z,X); returns false for anything else.
    bool planeOf(int a, int b, int& a0, int& a1) const {
        const int X = L_.axis('X'), Y = L_.axis('Y'), Z = L_.axis('Z');
        const auto is = [&](int p, int q) { return (a == p && b == q) || (a == q && b == p); };
        if (X >= 0 && Y >= 0 && is(X, Y)) a0 = X, a1 = Y;
        else if (Y >= 0 && Z >= 0 && is(Y, Z)) a0 = Y, a1 = Z;
        else if (Z >= 0 && X >= 0 && is(Z, X)) a0 = Z, a1 = X;
        else return false;
        return true;
    }

    void workingPlane(int& a0, int& a1) const {
        const int X = L_.axis('X'), Y = L_.axis('Y'), Z = L_.axis('Z');
        if (toolAxis_ >= 0 && toolAxis_ == Y) a0 = Z, a1 = X;
        else if (toolAxis_ >= 0 && toolAxis_ == X) a0 = Y, a1 = Z;
        else a0 = X, a1 = Y;
        if (a0 < 0 || a1 < 0) fail("the working plane's axes are missing on this machine");
    }

    void pole(const std::vector<std::string>& rest) {
        const PathWords w = words(rest, false, false);
        if (w.dr || w.rapid || w.machine) fail("CC takes the two coordinates of the circle centre only");
        if (w.axes.empty()) {
            workingPlane(poleA0_, poleA1_);
        } else {
            if (w.axes.size() != 2 || !planeOf(w.axes[0].axis, w.axes[1].axis, poleA0_, poleA1_))
                fail("CC needs two coordinates of one plane (X Y, Y Z or Z X)");
        }
        AxisVector c = pos_;
        unsigned ck = known_;
        apply(w, c, ck);
        const unsigned need = (1u << poleA0_) | (1u << poleA1_);
        poleKnown_ = (ck & need) == need;
        pc0_ = c[poleA0_];
        pc1_ = c[poleA1_];
    }

    /// End-point words of a circle in plane (a0, a1); other axes are not allowed.
    void circleEnd(const PathWords& w, int a0, int a1, AxisVector& end, unsigned& endKnown, const char* what, int helixAxis = -1) {
        for (const AxisWord& aw : w.axes)
            if (aw.axis != a0 && aw.axis != a1 && aw.axis != helixAxis)
                fail(fmt::format("{}: axis {} is not in the plane of the circle", what, L_.letter[aw.axis]));
        apply(w, end, endKnown);
    }

    void arcRow(bool ccw, int a0, int a1, double c0, double c1, const AxisVector& end, unsigned endKnown, std::string& row,
                PosesSummary& s) {
        // End tangent, for a following CT.
        const double r0 = end[a0] - c0, r1 = end[a1] - c1;
        Vec3 t = Vec3::Zero();
        const auto put = [&](int axis, double v) {
            for (int c = 0; c < 3; ++c)
                if (L_.axis("XYZ"[c]) == axis) t[c] = v;
        };
        put(a0, ccw ? -r1 : r1);
        put(a1, ccw ? r0 : -r0);
        if (t.norm() > 1e-12) tangent_ = t.normalized(), tangentKnown_ = true;
        pos_ = end;
        known_ = endKnown;
        emitRow(ccw ? "G3" : "G2", end, endKnown, row, s);
    }

    void circle(const std::string& key, const std::vector<std::string>& rest, std::string& row, PosesSummary& s) {
        const PathWords w = words(rest, false, key == "CR");
        if (w.rapid) fail(key + " with FMAX");
        AxisVector end = pos_;
        unsigned endKnown = known_;
        int a0 = -1, a1 = -1;
        if (key == "C") {
            if (poleA0_ < 0) fail("C without a circle centre: program CC first");
            a0 = poleA0_, a1 = poleA1_;
        } else if (w.axes.size() == 2 && planeOf(w.axes[0].axis, w.axes[1].axis, a0, a1)) {
        } else {
            workingPlane(a0, a1);
        }
        circleEnd(w, a0, a1, end, endKnown, key.c_str());
        const unsigned plane = (1u << a0) | (1u << a1);
        const bool startKnown = (known_ & plane) == plane;
        if (key == "C") {
            if (w.dr == 0) fail("C needs the direction of rotation DR+ or DR-");
            if (startKnown && poleKnown_) {
                const double rs = std::hypot(pos_[a0] - pc0_, pos_[a1] - pc1_), re = std::hypot(end[a0] - pc0_, end[a1] - pc1_);
                if (std::abs(rs - re) > 0.016)
                    fail(fmt::format("C: the end point is {:.4f} mm off the circle through the start point about CC", std::abs(rs - re)));
            }
            return arcRow(w.dr > 0, a0, a1, pc0_, pc1_, end, startKnown && poleKnown_ ? endKnown : endKnown & ~plane, row, s);
        }
        if (key == "CT" && !tangentKnown_) fail("CT needs a preceding contour element to be tangential to");
        if (!startKnown) return arcRow(w.dr > 0, a0, a1, 0, 0, end, endKnown & ~plane, row, s);
        const double s0 = pos_[a0], s1 = pos_[a1], e0 = end[a0], e1 = end[a1];
        const double dx = e0 - s0, dy = e1 - s1, d = std::hypot(dx, dy);
        if (key == "CR") {
            if (!w.hasR) fail("CR needs the radius R+ or R-");
            if (w.dr == 0) fail("CR needs the direction of rotation DR+ or DR-");
            const double r = std::abs(w.radius) * linScale();
            if (!(r > 0) || d < 1e-9) fail("CR with zero radius or coincident end points");
            if (d / 2 > r * (1 + 1e-9) + 1e-6) fail("CR: the radius is smaller than half the distance to the end point");
            const double h = d / 2 >= r ? 0.0 : std::sqrt(r * r - d * d / 4);
            // Centre to the right of start→end for a clockwise arc of at most 180° (R+), to the left when counter-clockwise.
            double side = w.dr < 0 ? 1.0 : -1.0;
            if (w.radius < 0) side = -side;
            return arcRow(w.dr > 0, a0, a1, (s0 + e0) / 2 + side * h * dy / d, (s1 + e1) / 2 - side * h * dx / d, end, endKnown,
                          row, s);
        }
        // CT: tangential to the previous contour element.
        double t0 = 0, t1 = 0;
        for (int c = 0; c < 3; ++c) {
            if (L_.axis("XYZ"[c]) == a0) t0 = tangent_[c];
            if (L_.axis("XYZ"[c]) == a1) t1 = tangent_[c];
        }
        const double tn = std::hypot(t0, t1);
        if (tn < 1e-9) fail("CT: the previous contour element does not move in the plane of the circle");
        t0 /= tn, t1 /= tn;
        const double n0 = -t1, n1 = t0;  // left normal
        const double dn = dx * n0 + dy * n1;
        if (std::abs(dn) < 1e-9 * std::max(1.0, d)) fail("CT: the end point lies on the tangent (no circle)");
        const double rho = (dx * dx + dy * dy) / (2 * dn);
        arcRow(rho > 0, a0, a1, s0 + rho * n0, s1 + rho * n1, end, endKnown, row, s);
    }

    void polar(const std::string& key, const std::vector<std::string>& rest, std::string& row, PosesSummary& s) {
        const PathWords w = words(rest, true, false);
        if (poleA0_ < 0 || !poleKnown_) fail(key + " without a pole: program CC first");
        const int a0 = poleA0_, a1 = poleA1_;
        const unsigned plane = (1u << a0) | (1u << a1);
        if ((known_ & plane) != plane) fail(key + ": the start position in the plane of the pole is not known");
        const double r0 = std::hypot(pos_[a0] - pc0_, pos_[a1] - pc1_);
        const double ang0 = std::atan2(pos_[a1] - pc1_, pos_[a0] - pc0_);
        AxisVector end = pos_;
        unsigned endKnown = known_;
        for (const AxisWord& aw : w.axes)
            if (aw.axis == a0 || aw.axis == a1) fail(fmt::format("{}: axis {} of the pole's plane in a polar block", key, L_.letter[aw.axis]));
        apply(w, end, endKnown);
        double r = r0, ang = ang0;
        if (key == "LP") {
            if (w.dr) fail("LP with DR+/DR-");
            if (w.hasPR) r = w.incPR ? r0 + w.pr * linScale() : w.pr * linScale();
        } else {
            if (w.hasPR) fail("CP takes no PR: the radius is the distance to the pole");
            if (w.dr == 0) fail("CP needs the direction of rotation DR+ or DR-");
        }
        if (w.hasPA) ang = w.incPA ? ang0 + w.pa * kDeg : w.pa * kDeg;
        if (!(r >= 0)) fail(key + ": negative polar radius");
        end[a0] = pc0_ + r * std::cos(ang);
        end[a1] = pc1_ + r * std::sin(ang);
        endKnown |= plane;
        if (key == "LP") {
            tangentOfLine(pos_, end, known_ & endKnown);
            pos_ = end;
            known_ = endKnown;
            return emitRow(w.rapid ? "G0" : "G1", end, endKnown, row, s);
        }
        arcRow(w.dr > 0, a0, a1, pc0_, pc1_, end, endKnown, row, s);
    }

    const AxisLayout& L_;
    const PosesOptions& o_;
    uint64_t line_ = 0;
    bool inch_ = false, ended_ = false;
    AxisVector pos_, shift_;
    unsigned known_ = 0;
    int toolAxis_ = -1;
    double tlo_ = 0;
    int poleA0_ = -1, poleA1_ = -1;
    double pc0_ = 0, pc1_ = 0;
    bool poleKnown_ = false;
    Vec3 tangent_ = Vec3::Zero();
    bool tangentKnown_ = false;
};

/// Code part of a physical line (before ';'), and whether it continues on the next line ('~' at the end).
std::string_view codePart(std::string_view raw, bool& continues) {
    std::string_view t = trim(raw);
    continues = !t.empty() && t.back() == '~';
    const size_t semi = raw.find(';');
    std::string_view code = semi == std::string_view::npos ? raw : raw.substr(0, semi);
    code = trim(code);
    if (!code.empty() && code.back() == '~') code.remove_suffix(1);
    return code;
}

}  // namespace

PosesSummary writeKlartextPoses(const AxisLayout& layout, LineReader& lines, std::ostream& csv, const PosesOptions& options) {
    PosesSummary s;
    s.dialect = Dialect::Heidenhain;
    Reader reader(layout, options);
    OutputBuffer out(csv);
    out.write("line,motion,X,Y,Z,A,B,C\n");
    std::string logical, row;
    uint64_t no = 0, start = 0;
    bool pending = false;
    Line line;
    const auto flush = [&] {
        row.clear();
        reader.block(logical, start, row, s);
        if (!row.empty()) out.write(row);
    };
    while (lines.next(line)) {
        ++no;
        ++s.lines;
        if (line.partial) throw InputError(options.inputName, static_cast<int>(no), "line longer than the read buffer");
        if (line.text.find('\0') != std::string_view::npos)
            throw InputError(options.inputName, static_cast<int>(no), "binary data in a Klartext program");
        bool continues = false;
        const std::string_view code = codePart(line.text, continues);
        if (!pending) {
            logical.clear();
            start = no;
        }
        if (!logical.empty() && !code.empty()) logical += ' ';
        logical += code;
        pending = continues;
        if (!pending) flush();
    }
    if (pending) flush();
    if (s.lines == 0) throw InputError(options.inputName, 0, "empty program");
    out.flush();
    return s;
}

PosesSummary writeKlartextPoses(const AxisLayout& layout, std::istream& in, std::ostream& csv, const PosesOptions& options) {
    LineReader lines(in, options.bufferSize);
    return writeKlartextPoses(layout, lines, csv, options);
}

}  // namespace cnccomp::pp
