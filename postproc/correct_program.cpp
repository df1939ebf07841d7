// `cnccomp correct` for a program: the head checked, the dialect chosen (Klartext to its own corrector), then the
// front end and the back end on one thread or two.
#include "postproc/correct_program.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include "cnccomp/error.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/correct_back_end.hpp"
#include "postproc/correct_front_end.hpp"
#include "postproc/klartext_correct.hpp"
#include "postproc/line_reader.hpp"

namespace cnccomp::postproc {

namespace {

using iso::FrontEnd;
using iso::ProgramCorrector;
using iso::Record;

/// Threads for a correction: --threads, or the machine's cores; two are used at most (front end and back end).
int threadsFor(const CorrectOptions& o) {
    if (o.threads > 0) return o.threads;
    return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

/// Records a batch holds: the front end reads a batch's blocks, then places them (FrontEnd::fill), then the back end
/// writes them, so that each part's code runs over many blocks in turn and stays in the instruction cache. Block by
/// block, the interpreter's, the solver's and the writer's code evicted each other: on the impeller in TCP mode
/// (cachegrind, 32 KiB L1i) the correction missed 552 times a line, now 72; the identity pass 83, now 2. A batch
/// closes after kLines records or kBytes of text (a piece of an overlong line fills one alone): constant memory.
constexpr size_t kLines = 64;
constexpr size_t kBytes = size_t{256} << 10;

/// The front end on its own thread, handing records to the back end (the calling thread) in batches, in program
/// order: the same computations as on one thread, so the same output byte for byte. Constant memory: a fixed number
/// of batches.
class Pipeline {
public:
    static constexpr int kBatches = 4;

    Pipeline() {
        for (Batch& b : batches_) b.records.resize(kLines);
    }

    template <class Consume>
    void run(FrontEnd& front, Consume&& consume) {
        std::thread producer([&] { produce(front); });
        try {
            for (int i = 0;; i = (i + 1) % kBatches) {
                Batch& b = batches_[i];
                {
                    std::unique_lock lock(mutex_);
                    changed_.wait(lock, [&] { return b.full; });
                }
                for (size_t k = 0; k < b.count; ++k) consume(b.records[k]);
                const bool last = b.last;
                const std::exception_ptr error = b.error;
                {
                    std::lock_guard lock(mutex_);
                    b.full = b.last = false;
                    b.error = nullptr;
                }
                changed_.notify_all();
                if (error) std::rethrow_exception(error);
                if (last) break;
            }
        } catch (...) {
            {
                std::lock_guard lock(mutex_);
                abort_ = true;
            }
            changed_.notify_all();
            producer.join();
            throw;
        }
        producer.join();
    }

private:
    struct Batch {
        std::vector<Record> records;
        size_t count = 0;
        bool full = false, last = false;
        std::exception_ptr error;
    };

    void produce(FrontEnd& front) {
        for (int i = 0;; i = (i + 1) % kBatches) {
            Batch& b = batches_[i];
            {
                std::unique_lock lock(mutex_);
                changed_.wait(lock, [&] { return !b.full || abort_; });
                if (abort_) return;
            }
            bool end = false;
            b.count = front.fill(b.records.data(), kLines, kBytes, end, b.error);
            b.last = end;
            const bool last = b.last;
            {
                std::lock_guard lock(mutex_);
                b.full = true;
            }
            changed_.notify_all();
            if (last) return;
        }
    }

    std::array<Batch, kBatches> batches_;
    std::mutex mutex_;
    std::condition_variable changed_;
    bool abort_ = false;
};

}  // namespace

CorrectSummary correctProgram(const MachineModel& machine, const DeviationSet& deviations, std::istream& in,
                              std::ostream& out, const CorrectOptions& given) {
    CorrectSummary s;
    LineReader reader(in, given.bufferSize);
    const std::string_view head = reader.head();
    checkTextHead(head, given.inputName);
    // No tool length given: a test program names the one it was made for in its header (cnccomp testprog).
    CorrectOptions withHeader;
    const std::optional<HeaderToolLength> header =
        given.setup.defaultToolLengthGiven ? std::nullopt : toolLengthFromHeader(head);
    if (header) {
        withHeader = given;
        withHeader.setup.defaultToolLength = header->mm;
        withHeader.setup.defaultToolLengthGiven = true;
    }
    const CorrectOptions& options = header ? withHeader : given;
    const auto noteHeader = [&](CorrectSummary& summary) {
        if (!header) return;
        summary.headerToolLength = header->mm;
        summary.headerToolLengthLine = header->line;
    };
    noteHeader(s);
    // HEIDENHAIN Klartext (BEGIN PGM among the first lines, whatever --dialect says): its own corrector.
    const int klartext = klartextHeaderLine(head);
    if (klartext > 0 || options.dialect == Dialect::Heidenhain) {
        if (klartext == 0)
            throw InputError(options.inputName, 0,
                             "--dialect heidenhain: no BEGIN PGM among the first lines, not a HEIDENHAIN Klartext program");
        CorrectSummary k = correctKlartextProgram(machine, deviations, reader, out, options);
        noteHeader(k);
        k.dialectDetected = !options.dialect || *options.dialect != Dialect::Heidenhain;
        k.dialectCertain = klartext > 0;
        k.dialectReason = "BEGIN PGM";
        return k;
    }
    if (options.dialect) {
        s.dialect = *options.dialect;
    } else {
        const DetectedDialect d = detectDialect(head);
        s.dialect = d.dialect;
        s.dialectDetected = true;
        s.dialectCertain = d.certain;
        s.dialectReason = d.reason;
    }
    OutputBuffer buffer(out);
    FrontEnd front(machine, deviations, options, s.dialect, reader);
    ProgramCorrector back(machine, deviations, options, s.dialect, s, buffer);
    auto consume = [&](Record& rec) {
        back.line(rec);
        if (options.progress && (rec.number & 0x1fff) == 0 && rec.lastPiece) options.progress(rec.bytesConsumed);
        if (rec.text.capacity() > (size_t{64} << 10)) std::string().swap(rec.text);  // a long line's buffer goes
    };
    if (threadsFor(options) < 2) {
        std::vector<Record> batch(kLines);
        for (bool end = false; !end;) {
            std::exception_ptr error;
            const size_t count = front.fill(batch.data(), kLines, kBytes, end, error);
            for (size_t k = 0; k < count; ++k) consume(batch[k]);
            if (error) std::rethrow_exception(error);
        }
    } else {
        Pipeline pipe;
        pipe.run(front, consume);
    }
    finishCorrection(buffer, reader, options, s);
    return s;
}

}  // namespace cnccomp::postproc
