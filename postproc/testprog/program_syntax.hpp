#pragma once
// NC syntax of the test programs: RS274NGC (LinuxCNC), Fanuc (ISO, O-number programs), Sinumerik (DIN 66025 /
// Siemens mode) and HEIDENHAIN conversational (Klartext). One writer per dialect behind one interface; every position
// is given in the controller's machine coordinates (mm, rad; written in mm and degrees).
// Sources: LinuxCNC G-code reference (G2/G3 with rotary words, G10 L2, G61, G91.1, G4 P seconds, (MSG,) comments);
// Fanuc 30i operator's manual B-64484EN (G02/G03 helical interpolation with additional axes, G10 L2 Pp, G04 P ms);
// Sinumerik 840D sl programming manual Fundamentals 6FC5398-1BP40 (G2/G3 with I/J/K incremental, G500, G4 F s, ';');
// HEIDENHAIN TNC 640 user's manual for Klartext programming 1303406 (BEGIN/END PGM, TOOL CALL, L … R0 FMAX,
// CC, C … DR+/-, STOP, CYCL DEF 7 datum shift, CYCL DEF 9 dwell). Points not confirmed are marked [G] in the output.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/machine.hpp"
#include "postproc/dialect.hpp"

namespace cnccomp::postproc::testprog {

// The dialect of a test program is postproc::Dialect (postproc/dialect.hpp; its names for test programs:
// postproc::parseDialect / postproc::dialectName with postproc::DialectUse::Write): Rs274ngc (LinuxCNC), Fanuc, Sinumerik, Heidenhain.
// Printer is not a test-program dialect: ProgramSyntax::make refuses it.

/// File extension with the dot: ".ngc", ".nc", ".mpf", ".h".
const char* programExtension(postproc::Dialect d);

/// Plane of a circular block: 17 (X, Y), 18 (Z, X), 19 (Y, Z).
struct ArcBlock {
    int plane = 17;
    int axis0 = -1, axis1 = -1;  ///< machine axes of the plane
    double c0 = 0, c1 = 0;       ///< centre, controller coordinates (mm)
    bool ccw = false;            ///< counter-clockwise seen from the + side of the plane normal (G3, DR+)
};

class ProgramSyntax {
public:
    /// `decimals`: digits after the point of positions (mm and deg).
    static std::unique_ptr<ProgramSyntax> make(postproc::Dialect d, const MachineModel& machine, int decimals);
    virtual ~ProgramSyntax() = default;

    /// Program start; `number` is the Fanuc O number.
    virtual void begin(const std::string& name, int number) = 0;
    virtual void comment(std::string_view text) = 0;
    /// Metric, absolute, XY plane, no cutter or tool-length compensation, work coordinates = machine coordinates.
    virtual void init() = 0;
    /// Rapid move of the axes in `mask` (bit = machine axis) to p (controller coordinates, mm and rad).
    virtual void rapid(const AxisVector& p, unsigned mask) = 0;
    /// Straight feed move of every axis to p.
    virtual void line(const AxisVector& p, double feed) = 0;
    /// Circular block from the current position to p (every axis; rotary axes turn with the arc's angle).
    virtual void arc(const AxisVector& p, const ArcBlock& a, double feed) = 0;
    /// Whether a circular block may carry rotary-axis words (else the caller writes straight blocks).
    virtual bool arcsWithRotaryAxes() const = 0;
    virtual void dwell(double seconds) = 0;
    /// Program stop (M0) with an operator message.
    virtual void stop(std::string_view message) = 0;
    virtual void end() = 0;
    /// The tool length L of the run (mm), before init(). LinuxCNC: init() writes G43.1 Z<L> (LinuxCNC then adds L to
    /// every Z word: the Z words are written as the machine coordinate minus L, so that the joints stay the same) and
    /// end() G49; the generated kinematics component of `cnccomp emit --controller linuxcnc` reads L from
    /// motion.tooloffset.z (tool-offset pin) and keeps the tool tip at L exact where the tool axis cannot follow.
    /// Returns whether the dialect passes L to the controller (LinuxCNC on a machine with a Z axis and L != 0).
    virtual bool passToolLength(double length) { (void)length; return false; }
    /// Notes on conventions not confirmed for this dialect ([G]), for the header.
    virtual std::vector<std::string> unconfirmed() const = 0;
    /// The program text so far.
    const std::string& text() const { return out_; }

protected:
    ProgramSyntax(const MachineModel& machine, int decimals) : machine_(machine), decimals_(decimals) {}
    /// Number with exactly `decimals` digits after the point (a point always); `plus` forces '+'.
    std::string number(double v, bool plus = false) const;
    /// Feeds and times: up to three decimals, trailing zeros dropped ("1000", "0.5").
    static std::string plain(double v);
    /// Axis words of p for the axes in mask, in X Y Z U V W A B C order: "X12.5 Y0.0 C90.0" (Heidenhain: X+12.5).
    /// The Z word is written minus zShift_ (LinuxCNC under G43.1, see passToolLength).
    std::string axisWords(const AxisVector& p, unsigned mask, bool plus) const;
    unsigned allAxes() const { return machine_.axisCount() >= 32 ? ~0u : (1u << machine_.axisCount()) - 1u; }
    /// Text for a comment: characters that would end it replaced, upper case where the dialect wants it.
    static std::string clean(std::string_view text, bool parentheses, bool upper);
    void emit(const std::string& line) { out_ += line + "\n"; }

    const MachineModel& machine_;
    int decimals_;
    double zShift_ = 0;  ///< mm taken off every Z word (the active tool length offset)
    std::string out_;
};

}  // namespace cnccomp::postproc::testprog
