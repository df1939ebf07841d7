#include "controllers/isg/isg_files.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/files.hpp"

namespace cnccomp::controllers::isg {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;

std::string formatIsgConfig(const IsgConfig& c, const std::string& header) {
    std::string s = header;
    s += "\n# logical axis numbers of the participating axes\n";
    std::vector<std::pair<int, char>> order;
    for (const auto& [letter, n] : c.axisNumber) order.emplace_back(n, letter);
    std::sort(order.begin(), order.end());
    for (const auto& [n, letter] : order) s += fmt::format("{:<24} {}\n", std::string(1, letter), n);
    s += "# kinematic chain from the workpiece over the machine origin to the tool tip (TF5240), and the number of\n# workpiece axes (the first letters of the chain)\n";
    s += fmt::format("{:<24} {}\n", "chain", c.chain);
    s += fmt::format("{:<24} {}\n", "workpiece_axes", c.workpieceAxes);
    for (size_t i = 0; i < c.files.size(); ++i) {
        s += fmt::format("{:<24} {}\n", fmt::format("file[{}]", i), c.files[i].first);
        s += fmt::format("{:<24} {}\n", fmt::format("file_format[{}]", i), c.files[i].second);
    }
    return s;
}

IsgConfig parseIsgConfig(const std::string& text, const std::string& name) {
    IsgConfig c;
    std::map<int, std::string> files, formats;
    for (const TextLine& l : splitLines(text)) {
        const std::string_view s = trim(l.text);
        if (s.empty() || s.front() == '#') continue;
        const auto tok = tokens(s);
        if (tok.size() != 2) throw InputError(name, l.number, "expected '<parameter> <value>'");
        const std::string key(tok[0]);
        if (key.size() == 1 && std::string("XYZABC").find(key[0]) != std::string::npos) {
            const double n = requireNumber(tok[1], name, l.number, "a logical axis number");
            if (n < 1 || n != static_cast<int>(n)) throw InputError(name, l.number, "logical axis numbers are whole numbers from 1");
            c.axisNumber[key[0]] = static_cast<int>(n);
        } else if (key == "chain") {
            c.chain = std::string(tok[1]);
            for (char ch : c.chain)
                if (std::string("XYZABC").find(ch) == std::string::npos)
                    throw InputError(name, l.number, fmt::format("chain '{}': axes are X Y Z A B C", c.chain));
        } else if (key == "negate" || key == "set_to_zero") {
            // P-VOLC-00009 and TF5280 "Modification of compensation values (optional)": a set of Cartesian axes.
            std::string& set = key == "negate" ? c.negate : c.setToZero;
            set = std::string(tok[1]);
            for (char ch : set)
                if (std::string("XYZ").find(ch) == std::string::npos)
                    throw InputError(name, l.number, fmt::format("{} '{}': the Cartesian axes X Y Z", key, set));
        } else if (key == "workpiece_axes") {
            const double n = requireNumber(tok[1], name, l.number, "a number of axes");
            if (n < 0 || n > 6 || n != static_cast<int>(n)) throw InputError(name, l.number, "workpiece_axes must be 0..6");
            c.workpieceAxes = static_cast<int>(n);
        } else if (key.starts_with("file[") || key.starts_with("file_format[")) {
            const size_t open = key.find('['), close = key.find(']');
            const auto idx = close == std::string::npos ? std::nullopt : parseNumber(key.substr(open + 1, close - open - 1));
            if (!idx || *idx < 0 || *idx > 9 || close + 1 != key.size()) throw InputError(name, l.number, fmt::format("bad index in '{}'", key));
            (key[4] == '[' ? files : formats)[static_cast<int>(*idx)] = std::string(tok[1]);
            if (key[4] != '[' && tok[1] != "ISG_CSV")
                throw InputError(name, l.number, fmt::format("file format '{}': this reader knows ISG_CSV only", tok[1]));
        } else {
            throw InputError(name, l.number, fmt::format("unknown parameter '{}'", key));
        }
    }
    for (const auto& [i, f] : files) {
        if (!formats.count(i)) throw InputError(name, 0, fmt::format("file[{}] has no file_format[{}]", i, i));
        c.files.emplace_back(f, formats[i]);
    }
    if (c.chain.empty()) throw InputError(name, 0, "no 'chain' line");
    return c;
}

std::vector<IsgBlock> parseIsgCsv(const std::string& text, const std::string& name) {
    std::vector<IsgBlock> blocks;
    bool needHeader = true;
    for (const TextLine& l : splitLines(text)) {
        std::string_view s = trim(l.text);
        if (const size_t c = s.find("//"); c != std::string_view::npos) s = trim(s.substr(0, c));
        if (s.empty()) continue;
        if (s.front() == '#') {
            if (trim(s.substr(1)).size() > 0) throw InputError(name, l.number, "a block break '#' stands alone on its line");
            if (!blocks.empty() && blocks.back().rows.empty()) throw InputError(name, l.number, "block without data rows");
            needHeader = true;
            continue;
        }
        const auto tok = tokens(s);
        if (needHeader) {
            IsgBlock b;
            b.headerLine = l.number;
            for (std::string_view t : tok) {
                if (std::find(b.columns.begin(), b.columns.end(), t) != b.columns.end())
                    throw InputError(name, l.number, fmt::format("column '{}' named twice", t));
                b.columns.emplace_back(t);
            }
            blocks.push_back(std::move(b));
            needHeader = false;
            continue;
        }
        IsgBlock& b = blocks.back();
        if (tok.size() != b.columns.size())
            throw InputError(name, l.number, fmt::format("{} values for {} columns", tok.size(), b.columns.size()));
        std::vector<double> row;
        for (size_t i = 0; i < tok.size(); ++i) row.push_back(requireNumber(tok[i], name, l.number, "a value of " + b.columns[i]));
        b.rows.push_back(std::move(row));
        b.rowLines.push_back(l.number);
    }
    if (blocks.empty()) throw InputError(name, 0, "no header line");
    if (blocks.back().rows.empty()) throw InputError(name, blocks.back().headerLine, "block without data rows");
    return blocks;
}

}  // namespace cnccomp::controllers::isg
