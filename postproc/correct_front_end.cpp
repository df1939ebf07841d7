#include "postproc/correct_front_end.hpp"

#include <algorithm>
#include <cmath>


#include "cnccomp/error.hpp"

namespace cnccomp::postproc::iso {

bool FrontEnd::next(Record& rec) {
    if (!read(rec)) return false;
    place(rec);
    return true;
}

size_t FrontEnd::fill(Record* recs, size_t max, size_t maxBytes, bool& end, std::exception_ptr& error) {
    size_t count = 0, bytes = 0;
    end = false;
    error = nullptr;
    try {
        while (count < max && bytes < maxBytes) {
            Record& rec = recs[count];
            if (!read(rec)) {
                end = true;
                break;
            }
            bytes += rec.text.size();
            ++count;
            if (placeBeforeReading(rec)) break;
        }
    } catch (...) {
        error = std::current_exception();
        end = true;
    }
    for (size_t k = 0; k < count; ++k) {
        try {
            place(recs[k]);
        } catch (...) {  // an error in an earlier record than the reading error's comes first
            error = std::current_exception();
            end = true;
            return k;
        }
    }
    return count;
}

void FrontEnd::place(Record& rec) {
    if (rec.partial) {
        if (rec.overlongCode && (rec.overlongModal || rec.r.words)) nomAt_.known = false;
        return;
    }
    switch (rec.r.kind) {
        case BlockKind::Empty: break;
        case BlockKind::NoMotion:
            if (rec.r.modeSwitch) switchMode(rec.r);
            break;
        case BlockKind::PassThrough: afterPassThrough(rec.r); break;
        case BlockKind::Move: move(rec); break;
    }
}

bool FrontEnd::read(Record& rec) {
    if (!reader_.next(line_)) return false;
    const Line& ln = line_;
    rec.text.assign(ln.text);
    rec.eolLen = static_cast<uint8_t>(std::min<size_t>(ln.eol.size(), 2));
    std::copy_n(ln.eol.begin(), rec.eolLen, rec.eol.begin());
    rec.number = ln.number;
    rec.bytesConsumed = reader_.bytesConsumed();
    rec.partial = ln.partial;
    rec.firstPiece = ln.firstPiece;
    rec.lastPiece = ln.lastPiece;
    rec.notices.clear();
    rec.frontRefused = rec.forgetOutput = rec.corrected = rec.unconverged = rec.outsideTravel = false;
    rec.overlongCode = rec.overlongModal = false;
    if (ln.partial) {
        if (ln.firstPiece) long_.reset();
        long_.feed(ln.text);
        if (ln.lastPiece && long_.code) {
            rec.overlongCode = true;
            rec.overlongModal = interp_.forgetOverlong(long_, rec.r);  // place() forgets the nominal position
        }
        return true;
    }
    lexBlock(rec.text, dialect_, rec.b, ln.number == 1);
    interp_.interpret(rec.text, rec.b, rec.r);
    rec.assumed = interp_.assumed();
    return true;
}

void FrontEnd::afterPassThrough(const BlockResult& r) {
    // The machine is where the nominal program puts it (joint mode); in TCP mode its joints are not followed.
    if (r.words || r.vectorGiven) {
        if (r.mode != ProgramMode::Joints) {
            nomAt_.known = false;
        } else {
            const MoveSpace joints{ProgramMode::Joints, 0.0, r.tipLength};
            nomAt_ = Where{(r.endKnown & all_) == all_, joints, ProgramPoint{r.end, Vec3(0, 0, -1)}, r.end, true};
        }
    }
    if (r.modeSwitch) nomAt_.known = false;  // a move in the block that switches TCP mode: unknown in the new mode
}

void FrontEnd::switchMode(const BlockResult& r) {
    // The controller's position is the same machine; what the program's numbers mean changes (LinuxCNC re-reads the
    // world position of the new kinematics at the switch: M66 E0 L0 in the M428/M429 remaps).
    const AxisMask rotary = layout_.rotaryAxes();
    if (convertWhere(corrector_, nomAt_, MoveSpace{r.mode, r.controlLength, r.tipLength}, r.end)) {
        interp_.setPosition(nomAt_.point.p, all_);
    } else {
        // Rotary angles are the same numbers in both modes; the linear positions are not known in the new one.
        interp_.setPosition(interp_.position(), interp_.known() & rotary);
    }
}

void FrontEnd::refuse(Record& rec, const char* reason) {
    rec.r.kind = BlockKind::PassThrough;
    rec.r.reason = reason;
    rec.r.report = true;
    afterPassThrough(rec.r);
}

void FrontEnd::move(Record& rec) {
    BlockResult& r = rec.r;
    // Field by field into the record: a MoveSpace built on the stack and copied whole was read back as 16 bytes over
    // its one-byte mode and a half of the lengths' store, a load the processor cannot forward (it waits for both).
    rec.space.mode = r.mode;
    rec.space.controlLength = r.controlLength;
    rec.space.toolLength = r.tipLength;
    const MoveSpace& space = rec.space;
    const bool tcp = space.mode != ProgramMode::Joints;
    if (tcp && !corrector_.tcp().supported()) {
        refuse(rec, corrector_.tcp().why());
        rec.forgetOutput = true;
        return;
    }
    const bool identity = corrector_.identity();
    const bool vector = space.mode == ProgramMode::TcpVector;
    bool nomStartKnown = (r.startKnown & all_) == all_;
    const AxisVector guess = nomAt_.known && nomAt_.jointsValid ? nomAt_.joints : r.end;

    // Nominal end point in program space (vector mode: the programmed vector, tip → spindle, or the kept one).
    ProgramPoint& nomEnd = rec.nomEnd;
    ProgramPoint& nomStart = rec.nomStart;
    nomEnd.p = r.end;
    nomStart.p = r.start;
    nomEnd.v = nomStart.v = Vec3(0, 0, -1);
    if (vector) {
        const bool nomVector = nomStartKnown && vectorOf(corrector_, nomAt_, guess);
        nomStartKnown = nomStartKnown && nomVector;
        nomStart.v = nomAt_.vector;
        nomEnd.v = r.vectorGiven ? Vec3(-r.vector[0], -r.vector[1], -r.vector[2]).normalized() : nomAt_.vector;
        if (!r.vectorGiven && !nomVector) {
            refuse(rec, "tool vector not known yet (no I J K / A3 B3 C3 given since TCP was switched on)");
            return;
        }
    }
    rec.nomStartKnown = nomStartKnown;

    // Corrected end point: nominal machine coordinates, the erroneous machine's solution, its program position.
    AxisVector& cNom = rec.cNom;
    AxisVector& cEnd = rec.cEnd;
    NominalPose nomPose;
    if (identity && !vector) {
        cNom = r.end;  // not the machine coordinates in TCP mode: not used for anything but guesses
    } else if (!corrector_.toJoints(space, nomEnd, guess, cNom, &nomPose)) {
        refuse(rec, "the controller's TCP kinematics cannot reach this tool vector (no rotary solution)");
        rec.frontRefused = true;
        return;
    }
    rec.tipResidual = rec.axisResidual = 0;
    if (identity) {
        cEnd = cNom;
    } else {
        const EndPointSolver::Result s = endPoints_.solve(corrector_, layout_, options_, space.toolLength, cNom, &nomPose,
                                                          {r.tipLengthAssumed, rec.number}, cEnd);
        rec.tipResidual = s.tipResidual;
        rec.axisResidual = s.axisResidual;
        rec.unconverged = s.unconverged;
        rec.corrected = s.corrected;  // the back end writes cEnd's program position (toProgram)
        if (s.unconverged) rec.note(true, s.failure);
    }
    if (!(identity && tcp && !vector) &&
        travel_.check(cNom, cEnd, [&](std::string message) { rec.note(true, std::move(message)); }))
        rec.outsideTravel = true;
    rec.jointsComputed = !identity || vector || !tcp;
    nomAt_ = Where{true, space, nomEnd, cNom, rec.jointsComputed, nomEnd.v, vector};
}

}  // namespace cnccomp::postproc::iso
