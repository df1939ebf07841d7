#pragma once
// `cnccomp poses`: every motion endpoint of a program in absolute machine coordinates, as the controller's modal
// semantics put it (work offsets, G20/G21, G90/G91, G43, arcs, lathe diameter mode …): CSV
// `line,motion,X,Y,Z,A,B,C` in mm and degrees; unknown positions are empty cells.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "postproc/modal.hpp"

namespace cnccomp::postproc {

struct PosesOptions {
    std::optional<Dialect> dialect;  ///< nullopt: detected
    Setup setup;
    bool rotaryShortest = false;
    std::string inputName = "<input>";
    size_t bufferSize = size_t{1} << 20;
    int tcpOnM = -1, tcpOffM = -1;   ///< user-declared tool-tip programming switches (e.g. M428 / M429)
};

struct PosesSummary {
    Dialect dialect = Dialect::Rs274ngc;
    uint64_t lines = 0, rows = 0, moves = 0, passedThrough = 0;
};

/// Writes the CSV (header first). One row per evaluated G0–G3 move (motion "G0" … "G3") and per block that moves
/// axes without being evaluable (motion "-": a G53 move, a canned cycle, a move with an expression …). Moves in
/// tool-tip (TCP) mode are labelled "G1 TCP" …: their X Y Z are the programmed tool point (world frame, work offset
/// applied), not machine coordinates.
PosesSummary writePoses(const AxisLayout& layout, std::istream& in, std::ostream& csv, const PosesOptions& options);

}  // namespace cnccomp::postproc
