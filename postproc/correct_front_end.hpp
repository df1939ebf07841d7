#pragma once
// The front end of the RS274NGC-family corrector: lines → lexed blocks → interpreted blocks → corrected end points.
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

    /// The next line into `rec`; false at the end of the input.
    bool next(Record& rec);

private:
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
