#pragma once
// `cnccomp correct`: stream a G-code program block by block, correct every evaluable motion endpoint for the
// machine's deviations (postproc/correction.hpp), subdivide where needed, and write every byte that is not
// changed exactly as read. Constant memory: a fixed read buffer, a fixed write buffer, capped notice lists.
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "postproc/correction.hpp"
#include "postproc/dialect.hpp"
#include "postproc/setup.hpp"

namespace cnccomp::postproc {

struct CorrectOptions {
    std::optional<Dialect> dialect;  ///< nullopt: detected from the head of the program
    Setup setup;
    bool rotaryShortest = false;     ///< modulo rotary axes: absolute words in [0, 360) reached the shortest way
    CorrectorOptions corrector;
    int decimals = -1;               ///< decimals of changed numbers; -1: the program's own (see README)
    std::string inputName = "<input>";
    std::function<void(uint64_t bytesRead)> progress;  ///< called every few thousand lines
    std::ostream* report = nullptr;  ///< optional CSV "line,kind,message" of every notice (unbounded, streamed)
    size_t bufferSize = size_t{1} << 20;  ///< read buffer: longest line parsed; longer lines pass through
    int tcpOnM = -1, tcpOffM = -1;   ///< user-declared TCP switches (--tcp-on M428 --tcp-off M429), -1 none
    /// Threads: 1 reads, corrects and writes on the calling thread; 2 or more run the front end (reading, lexing,
    /// interpreting, end-point correction) on a second thread, the back end (path check, splitting, writing) on the
    /// calling one — the same output byte for byte; 0: the machine's cores.
    int threads = 0;
    /// A tool length nobody gave (no --tool-length L, setup file or test program header) is refused where a rotary
    /// move's correction depends on it (refuseAssumedToolLength); false: it is taken as 0 (library callers that set
    /// Setup themselves). `cnccomp correct` sets it.
    bool requireToolLength = false;
};

struct Notice {
    uint64_t line = 0;
    std::string message;
};

struct CorrectSummary {
    Dialect dialect = Dialect::Rs274ngc;
    bool dialectDetected = false;   ///< auto-detected (not given)
    bool dialectCertain = false;
    std::string dialectReason;
    uint64_t lines = 0;             ///< lines read
    uint64_t blocks = 0;            ///< lines with code (not blank / comment-only)
    uint64_t moves = 0;             ///< evaluated G0–G3 moves
    uint64_t corrected = 0;         ///< blocks whose text changed
    uint64_t split = 0;             ///< moves subdivided (or arcs turned into lines)
    uint64_t addedLines = 0;        ///< lines inserted by subdivision
    uint64_t arcsToLines = 0;
    uint64_t passedThrough = 0;     ///< blocks written unchanged because they could not be evaluated
    uint64_t notCorrected = 0;      ///< of which ordinary moves deliberately left alone (G53, reference returns)
    double maxLinearCorrection = 0; ///< mm
    uint64_t maxLinearLine = 0;
    double maxRotaryCorrection = 0; ///< rad
    uint64_t maxRotaryLine = 0;
    double maxTipResidual = 0;      ///< mm: solver residual at endpoints
    double maxAxisResidual = 0;     ///< rad: tool-axis residual at endpoints (non-zero only near singular poses)
    double maxPathDeviation = 0;    ///< mm: at the checked midpoints / arc samples
    uint64_t boundedChecks = 0;     ///< midpoint checks settled by the midpoint bound, not evaluated (not printed)
    uint64_t unconverged = 0;
    uint64_t limited = 0;           ///< moves where the subdivision limit left the tolerance unmet
    uint64_t tcpMoves = 0;          ///< moves corrected in tool-tip (TCP) mode
    uint64_t outsideTravel = 0;     ///< moves with a nominal or corrected position outside an axis' travel
    uint64_t clampedTolerance = 0;  ///< moves checked at the output resolution instead of --tol-um (too fine)
    double toleranceFloor = 0;      ///< mm: largest such resolution bound
    uint64_t offPathStarts = 0;     ///< moves starting off the nominal path (after a block passed through)
    double headerToolLength = 0;    ///< mm: the tool length read from the program's header (test programs)
    uint64_t headerToolLengthLine = 0;  ///< its line; 0: none was read (given on the command line or not at all)
    /// Blocks left uncorrected that --strict counts: reported pass-through, unconverged or unmet tolerance.
    uint64_t uncorrected() const { return (passedThrough - notCorrected) + unconverged + limited; }
    std::vector<Notice> passThrough;  ///< first kMaxNotices
    std::vector<Notice> warnings;     ///< first kMaxNotices
    uint64_t warningCount = 0;
    uint64_t bytesIn = 0, bytesOut = 0;
    static constexpr size_t kMaxNotices = 100;
};

/// Corrects the program read from `in` into `out`. Throws InputError (naming options.inputName) for an empty or
/// binary input; everything else it cannot evaluate is passed through and reported in the summary. A HEIDENHAIN
/// Klartext program (BEGIN PGM) goes to correctKlartextProgram (postproc/klartext_correct.hpp), which also throws
/// InputError for a malformed block.
CorrectSummary correctProgram(const MachineModel& machine, const DeviationSet& deviations, std::istream& in,
                              std::ostream& out, const CorrectOptions& options);

/// The summary as text for the terminal (several lines).
std::string formatSummary(const CorrectSummary& s, size_t maxListed = 20);

/// A notice in the summary (the first kMaxNotices of each list) and as a line "line,kind,message" of `report`.
void addNotice(CorrectSummary& summary, std::ostream* report, bool warning, uint64_t line, std::string message);

class OutputBuffer;
class LineReader;
/// The end of a correction (RS274NGC family and Klartext alike): the output flushed, the last progress report, the
/// bytes read and written in the summary.
void finishCorrection(OutputBuffer& out, const LineReader& reader, const CorrectOptions& options, CorrectSummary& s);

/// The finest path tolerance the written digits can hold at a move ending at `end` (program space): each end point is
/// off by up to half a digit per axis — √(linear axes) half-digits of `linDecimals` (mm, or inch digits), and in joint
/// mode √(rotary axes) half-digits of `rotDecimals` (degrees) times the rotary axes' lever arm at the pose.
double digitsTolerance(Corrector& corrector, const MoveSpace& space, const AxisVector& end, int linDecimals,
                       int rotDecimals, bool inch, int linearAxes, int rotaryAxes);
/// --tol-um (tolMm), or that bound when the tolerance is finer than the digits hold: then counted in the summary and
/// said once (a warning at `line`; `warned` remembers it).
double toleranceWithin(double tolMm, double floorMm, int linDecimals, CorrectSummary& summary, std::ostream* report,
                       uint64_t line, bool& warned);

/// How far along the tool `cnccomp correct` looks when no tool length was given (mm) [G]: a tool point this much
/// further from the spindle than the assumed one (0 mm) stands for "the length the program was meant for".
constexpr double kToolLengthProbeMm = 100.0;

/// A tool length nobody gave (BlockResult::tipLengthAssumed): where a rotary axis is off 0 and the end point `cEnd`
/// corrected for the tool point at `toolLength` leaves the point kToolLengthProbeMm further along the tool more than
/// `toleranceMm` off its nominal place (`cNom`), the correction depends on that length: throws InputError naming
/// `name`:`line` and asking for --tool-length (0 when meant). On a five-axis machine whose rotary axes match the tool
/// axis exactly the whole tool line is corrected and nothing is refused.
void refuseAssumedToolLength(Corrector& corrector, const AxisLayout& layout, const AxisVector& cNom,
                             const AxisVector& cEnd, double toolLength, double toleranceMm, const std::string& name,
                             uint64_t line);

/// The tool length a test program names in its header (`cnccomp testprog`: "… cnccomp correct --tool-length L",
/// postproc/testprog/test_program.cpp), searched case-insensitively in the first 200 lines of `head`.
struct HeaderToolLength {
    double mm = 0;
    uint64_t line = 0;
};
std::optional<HeaderToolLength> toolLengthFromHeader(std::string_view head);

/// Refuses files that are empty or binary (NUL bytes, mostly control bytes) in their first bytes.
void checkTextHead(std::string_view head, const std::string& name);

}  // namespace cnccomp::postproc
