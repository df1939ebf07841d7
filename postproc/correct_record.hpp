#pragma once
// The RS274NGC-family corrector (`cnccomp correct`, postproc/correct_program.cpp) in two halves: the front end
// (postproc/correct_front_end.hpp) reads, interprets and corrects end points; the back end (correct_back_end.hpp)
// checks and splits the path and writes the text. This is what passes between them: one Record per line, and where the
// nominal or output program is (Where).
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "postproc/correction.hpp"
#include "postproc/lexer.hpp"
#include "postproc/modal.hpp"

namespace cnccomp::postproc::iso {

/// Where the nominal program or the output program is (unrounded), in the space it was read in; machine coordinates
/// and the tool vector there are computed when needed.
struct Where {
    bool known = false;
    MoveSpace space;
    ProgramPoint point;
    AxisVector joints;
    bool jointsValid = false;
    Vec3 vector = Vec3(0, 0, -1);
    bool vectorValid = false;
};

inline bool jointsOf(Corrector& corrector, Where& w, const AxisVector& guess) {
    if (!w.known) return false;
    if (!w.jointsValid) w.jointsValid = corrector.toJoints(w.space, w.point, guess, w.joints);
    return w.jointsValid;
}

inline bool vectorOf(Corrector& corrector, Where& w, const AxisVector& guess) {
    if (!w.known) return false;
    if (w.vectorValid) return true;
    if (w.space.mode == ProgramMode::TcpVector) {
        w.vector = w.point.v;
    } else {
        if (!jointsOf(corrector, w, guess)) return false;
        ProgramPoint p;
        corrector.toProgram(MoveSpace{ProgramMode::TcpVector, w.space.controlLength, w.space.toolLength}, w.joints, p);
        w.vector = p.v;
    }
    w.vectorValid = true;
    return true;
}

/// After a TCP mode switch: the same machine position read in the new mode (false when it is not known).
inline bool convertWhere(Corrector& corrector, Where& w, const MoveSpace& space, const AxisVector& guess) {
    if (!jointsOf(corrector, w, guess)) {
        w.known = false;
        return false;
    }
    const AxisVector joints = w.joints;
    w.space = space;
    corrector.toProgram(space, joints, w.point);
    w.joints = joints;
    w.jointsValid = true;
    w.vectorValid = false;
    return true;
}

/// One line as the front end read it — lexed, interpreted and, for a move, its end point corrected — handed in program
/// order to the back end, which checks and splits the path and writes the text. Every value the back end needs from
/// the front end's running state is in here, so the two can run on two threads with the same results as on one.
struct Record {
    std::string text;
    std::array<char, 2> eol{};
    uint8_t eolLen = 0;
    uint64_t number = 0, bytesConsumed = 0;
    bool partial = false, firstPiece = true, lastPiece = true;
    LexedBlock b;
    BlockResult r;
    AxisMask assumed = 0;           ///< axes taken at an assumed position (Interpreter::assumed) after this block
    bool overlongCode = false;      ///< last piece of an overlong line that holds code
    bool overlongModal = false;     ///< … whose codes may change any mode (Interpreter::forgetOverlong)
    // A move (r.kind Move), or one the front end refused (r.kind PassThrough, frontRefused):
    bool frontRefused = false;      ///< counted as a move, then passed through (r.reason says why)
    bool forgetOutput = false;      ///< the output position is unknown after it (TCP on a machine without X Y Z)
    MoveSpace space;
    bool nomStartKnown = false, corrected = false, unconverged = false, outsideTravel = false, jointsComputed = false;
    ProgramPoint nomStart, nomEnd;
    AxisVector cNom, cEnd;
    double tipResidual = 0, axisResidual = 0;  ///< of the end point's solution
    std::vector<std::pair<bool, std::string>> notices;  ///< (warning, text) raised by the front end, in order
    std::string_view eolView() const { return {eol.data(), eolLen}; }
    void note(bool warning, std::string message) { notices.emplace_back(warning, std::move(message)); }
};

}  // namespace cnccomp::postproc::iso
