#pragma once
// The one CSV reader of cnccomp (deviation files, maps, R-test traces, eccentricities, measured ball-bar traces, the
// generic backend's grid map). What it accepts, as spreadsheets and instrument software write CSV (RFC 4180 plus
// the common variants):
//  - a UTF-8 byte-order mark is skipped ("CSV UTF-8" in Excel / LibreOffice writes one); UTF-16 text is refused;
//  - LF or CRLF line ends; blank lines and lines whose first character is '#' are skipped (a `# key: value` comment
//    is kept as metadata with its line);
//  - the separator is taken from the header line (the first other line): ';' if it holds one outside quotes, else a
//    tab if it holds one, else ','. Every row uses the header's separator;
//  - a cell may be quoted ("..."), with "" for a quote inside; a quote left open at the end of a line is an error
//    (a cell never spans lines);
//  - cells are trimmed of blanks; every row keeps its 1-based line number for messages.
// Only regular files are read: a folder, a FIFO, a device is refused before it is opened (opening a FIFO would block).
// Rows are read one at a time (CsvReader): a large file streams without being held in memory.
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/machine.hpp"

namespace cnccomp::io {

/// Throws InputError unless `path` names a regular file (or a link to one): a folder is "a folder, not a file", a
/// FIFO / socket / device is named as such and never opened (opening a FIFO blocks until a writer comes). Every
/// reader calls it before opening its input (CsvReader, xml::load).
void requireRegularFile(const std::string& path);

struct CsvRow {
    int line = 0;
    std::vector<std::string> cells;
};

/// A `# key: value` comment line.
struct CsvComment {
    std::string key, value;
    int line = 0;
};

/// Reads a CSV source row by row (see the file comment for the accepted dialect).
class CsvReader {
public:
    /// Opens a file (requireRegularFile first). Throws InputError.
    explicit CsvReader(const std::string& path);
    /// Reads `text` (held by the caller while the reader is used); `name` names it in messages.
    CsvReader(std::string_view text, const std::string& name);
    ~CsvReader();
    CsvReader(const CsvReader&) = delete;
    CsvReader& operator=(const CsvReader&) = delete;

    /// The header (the first line that is neither blank nor a comment). Throws InputError for an empty file.
    const CsvRow& header();
    /// The next data row; false at the end. Comments before it are appended to comments().
    bool next(CsvRow& row);
    char separator() const { return separator_; }
    const std::vector<CsvComment>& comments() const { return comments_; }
    /// The comment lines before the header as they are (trimmed, from the '#'), with or without a key.
    const std::vector<CsvRow>& preamble() const { return preamble_; }
    const std::string& path() const { return path_; }
    /// Last line number read.
    int line() const { return line_; }

private:
    bool nextLine(std::string_view& out);
    /// A blank or '#' line: true, and a `# key: value` comment kept with its line.
    bool skipBlankOrComment(std::string_view s);
    void split(std::string_view line, std::vector<std::string>& cells) const;

    std::string path_;
    std::unique_ptr<std::ifstream> file_;
    std::string_view text_;
    size_t textPos_ = 0;
    std::string buffer_;
    int line_ = 0;
    bool haveHeader_ = false;
    char separator_ = ',';
    CsvRow header_;
    std::vector<CsvComment> comments_;
    std::vector<CsvRow> preamble_;  ///< one cell each
};

/// "tab" or the separator itself, for messages.
std::string separatorName(char separator);

struct CsvTable {
    std::string path;
    CsvRow header;
    std::vector<CsvRow> rows;
    char separator = ',';
    /// The comment lines before the header (CsvReader::preamble): one cell each, the line from its '#'.
    std::vector<CsvRow> preamble{};
    /// Column index by header name, or -1.
    int column(const std::string& name) const;
    /// Column index by header name; throws InputError naming the file when missing.
    int requireColumn(const std::string& name) const;
    /// Cell as a finite number; throws InputError with file:line when not. Empty cells give nullopt. Where the
    /// separator is ';' or a tab, a decimal comma ("1,5") is read as 1.5 (a spreadsheet's export in a comma locale).
    std::optional<double> number(const CsvRow& row, int column) const;
    double requireNumber(const CsvRow& row, int column) const;
    const std::string& cell(const CsvRow& row, int column) const;
};

/// Reads a CSV file whose first non-comment line is the header. Throws InputError on a missing or non-regular file,
/// binary content, or rows with more cells than the header (saying so when a decimal comma is the likely cause).
CsvTable readCsv(const std::string& path);
/// The same from text held in memory (`name` for messages).
CsvTable parseCsv(std::string_view text, const std::string& name);

/// A number cell: decimal point, or (with `decimalComma`) a decimal comma. nullopt when the text is not a number.
std::optional<double> parseCsvNumber(std::string_view cell, bool decimalComma);

/// Column of machine axis `axis` in cnccomp's CSV files: its name and unit, e.g. "X_mm", "C_deg".
std::string axisColumn(const MachineModel& m, int axis);

}  // namespace cnccomp::io
