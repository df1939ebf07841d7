#pragma once
// The front end of the RS274NGC-family corrector: lines → lexed blocks → interpreted blocks → corrected end points.
#include <exception>

#include "cnccomp/deviations.hpp"
#include "cnccomp/machine.hpp"
#include "postproc/correct_move.hpp"
#include "postproc/correct_program.hpp"
#include "postproc/correct_record.hpp"
#include "postproc/line_reader.hpp"

namespace cnccomp::postproc::iso {

/// The front end: reads lines, lexes and interprets them, follows the nominal program and corrects move end points
/// (each from the previous one's correction: warm start and continuity).
class FrontEnd {
public:
    FrontEnd(const MachineModel& m, const DeviationSet& d, const CorrectOptions& o, Dialect dialect, LineReader& reader)
        : options_(o),
          dialect_(dialect),
          layout_(AxisLayout::fromMachine(m)),
          interp_(layout_, InterpreterOptions{dialect, o.setup, o.rotaryShortest, o.tcpOnM, o.tcpOffM}),
          corrector_(m, d, o.corrector),
          reader_(reader),
          endPoints_(layout_.count),
          travel_(m, layout_) {
        all_ = layout_.all();
    }

    /// The next line into `rec`; false at the end of the input. The same as read() then place().
    bool next(Record& rec);

    /// Up to `max` records into recs[0 …], each read and then placed: all of them read first, then all placed, so that
    /// the interpreter's code and the kinematics' code each run over several blocks in turn (a block's place() changes
    /// nothing its successors' read() sees, except at a TCP mode switch: the batch ends there). Fewer records at a mode
    /// switch, after `maxBytes` of text, or at the end of the input (`end` true). An exception thrown for record k is
    /// stored in `error` (then `end` is true) and the records before it are returned, placed: the same records and the
    /// same computations in the same order as next() one record at a time.
    size_t fill(Record* recs, size_t max, size_t maxBytes, bool& end, std::exception_ptr& error);

private:
    /// The next line into `rec`, lexed and interpreted; false at the end of the input.
    bool read(Record& rec);
    /// Follows the nominal program over a record read() gave and corrects its end point.
    void place(Record& rec);
    /// A record after which the interpreter needs place() before it reads on (it re-reads the position at a switch).
    static bool placeBeforeReading(const Record& rec) {
        return !rec.partial && rec.r.kind == BlockKind::NoMotion && rec.r.modeSwitch;
    }
    void afterPassThrough(const BlockResult& r);
    void switchMode(const BlockResult& r);
    void move(Record& rec);
    void refuse(Record& rec, const char* reason);

    const CorrectOptions& options_;
    Dialect dialect_;
    AxisLayout layout_;
    Interpreter interp_;
    Corrector corrector_;
    LineReader& reader_;
    Line line_;
    OverlongLine long_;
    Where nomAt_;
    EndPointSolver endPoints_;
    TravelCheck travel_;
    AxisMask all_ = 0;
};

}  // namespace cnccomp::postproc::iso
