#include "postproc/interp_read.hpp"

#include <cctype>
#include <cmath>
#include <string>

namespace cnccomp::postproc {

namespace {

bool isControlFlowKeyword(std::string_view id) {
    static constexpr std::string_view kFlow[] = {"IF",    "GOTO",  "GOTOF",   "GOTOB", "GOTOC",   "WHILE", "DO",
                                                 "END",   "ENDWHILE", "LOOP", "ENDLOOP", "REPEAT", "UNTIL", "FOR",
                                                 "ENDFOR", "SUB",  "ENDSUB",  "CALL",  "RETURN",  "RET",   "ENDIF",
                                                 "ELSE",  "ELSEIF", "BREAK",  "CONTINUE", "THEN"};
    for (auto f : kFlow) {
        if (id.size() < f.size()) continue;
        bool same = true;
        for (size_t i = 0; i < f.size() && same; ++i)
            same = static_cast<char>(std::toupper(static_cast<unsigned char>(id[i]))) == f[i];
        if (same && (id.size() == f.size() || std::isdigit(static_cast<unsigned char>(id[f.size()])))) return true;
    }
    return false;
}

enum class Keyword { Harmless, TcpOn, TcpOff, TransformOn, MachineCoords, DiameterOn, DiameterOff, Unknown };

Keyword sinumerikKeyword(std::string_view id, bool call) {
    std::string up;
    for (char c : id) up.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (call) return up == "MSG" ? Keyword::Harmless : Keyword::Unknown;
    static constexpr std::string_view kHarmless[] = {
        "SOFT",    "BRISK",   "DRIVE",   "FFWON",  "FFWOF",  "CFC",     "CFTCP",  "CFIN",    "ORIWKS",  "ORIMKS",
        "ORIAXES", "ORIVECT", "ORIEULER", "ORIRPY", "COMPCAD", "COMPCURV", "COMPOF", "COMPON", "UPATH",   "SPATH",
        "STOPRE",  "CUT2D",   "CUT2DF",  "CUT3DC", "FNORM",  "FLIN",    "FCUB",   "WALIMON", "WALIMOF", "G291",
        "G290",    "SPIF1",   "SPIF2",   "OFFN",   "DIAM90", "FGROUP",  "BTAN",   "ETAN",    "FFWOFF"};
    for (auto h : kHarmless)
        if (up == h) return up == "DIAM90" ? Keyword::DiameterOn : Keyword::Harmless;
    if (up == "TRAORI") return Keyword::TcpOn;
    if (up == "TRAFOOF") return Keyword::TcpOff;
    if (up == "TRANSMIT" || up == "TRACYL" || up == "TRANS" || up == "ATRANS" || up == "ROT" || up == "AROT" ||
        up == "SCALE" || up == "ASCALE" || up == "MIRROR" || up == "AMIRROR" || up == "TRAANG")
        return Keyword::TransformOn;
    if (up == "SUPA") return Keyword::MachineCoords;
    if (up == "DIAMON") return Keyword::DiameterOn;
    if (up == "DIAMOF") return Keyword::DiameterOff;
    return Keyword::Unknown;
}

/// Multi-letter words: control flow in every dialect, the Sinumerik keywords and calls.
void readKeywords(std::string_view line, const LexedBlock& b, Dialect dialect, BlockWords& w) {
    if (b.identifierCount >= LexedBlock::kMaxIdentifiers) w.unknownKeyword = true;
    for (int k = 0; k < b.identifierCount; ++k) {
        const std::string_view id = b.identifier(line, k);
        if (isControlFlowKeyword(id)) {
            w.flow = true;
            continue;
        }
        if (dialect != Dialect::Sinumerik) {
            w.unknownKeyword = true;
            continue;
        }
        size_t after = b.identifiers[k].end;
        while (after < line.size() && (line[after] == ' ' || line[after] == '\t')) ++after;
        const bool call = after < line.size() && line[after] == '(';
        switch (sinumerikKeyword(id, call)) {
            case Keyword::Harmless: break;
            case Keyword::TcpOn: w.tcpOn = true; break;
            case Keyword::TcpOff: w.tcpOff = true; break;
            case Keyword::TransformOn: w.transformOn = true; break;
            case Keyword::MachineCoords: w.machineKeyword = true; break;
            case Keyword::DiameterOn: w.diameterKeyword = 1; break;
            case Keyword::DiameterOff: w.diameterKeyword = 0; break;
            case Keyword::Unknown: w.unknownKeyword = true; break;
        }
    }
    if (!w.flow && !w.unknownKeyword) w.flags &= ~(kIdentifier | kCall);
}

/// A G word as code × 10 (G43.4 → 434); sets gProblem when it is not a plain G code.
void readG(const Word& word, int i, BlockWords& w) {
    if (word.kind != ValueKind::Number || word.value < 0 || word.value >= 10000) {
        w.gProblem = true;
        return;
    }
    const int code = static_cast<int>(std::lround(word.value * 10));
    if (std::fabs(word.value * 10 - code) > 1e-6 || w.nG >= 16) {
        w.gProblem = true;
        return;
    }
    w.gCode[w.nG] = code;
    w.gWord[w.nG++] = i;
}

/// M0 M1 M2 M30 M60 stop; M98 M97 M198 call and M99 (Sinumerik M17) end a subprogram; the user's TCP switches.
void readM(const Word& word, const InterpreterOptions& options, BlockWords& w, BlockResult& r) {
    if (word.kind != ValueKind::Number || word.value != std::floor(word.value)) return;
    const int m = static_cast<int>(word.value);
    if (m == 0 || m == 1 || m == 2 || m == 30 || m == 60) r.stop = true;
    if (m == options.tcpOnM && std::fabs(word.value - m) == 0) w.userTcpOn = true;
    if (m == options.tcpOffM && std::fabs(word.value - m) == 0) w.userTcpOff = true;
    if (options.dialect != Dialect::Printer) {
        if (m == 98 || m == 97 || m == 198) w.mCall = true;
        if (m == 99 || (options.dialect == Dialect::Sinumerik && m == 17)) w.mSubEnd = true;
    }
}

}  // namespace

void readBlockWords(std::string_view line, const LexedBlock& b, const AxisLayout& layout,
                    const InterpreterOptions& options, BlockWords& w, BlockResult& r) {
    w.flags = b.flags;
    if (w.flags & (kIdentifier | kCall)) readKeywords(line, b, options.dialect, w);
    for (int i = 0; i < b.count; ++i) {
        const Word& word = b.words[i];
        const char c = word.letter;
        if (word.ext != 0) {
            // Sinumerik A3= B3= C3=: components of the tool vector (TRAORI); other extended addresses unsupported.
            if (word.ext == 3 && (c == 'A' || c == 'B' || c == 'C')) r.vectorWord[c - 'A'] = static_cast<int8_t>(i);
            else w.extProblem = true;
            continue;
        }
        if (c == 'G') {
            readG(word, i, w);
            continue;
        }
        const int a = layout.axis(c);
        if (a >= 0) {
            if (r.axisWord[a] >= 0) w.duplicateAxis = true;
            r.axisWord[a] = static_cast<int8_t>(i);
            r.words |= 1u << a;
            continue;
        }
        switch (c) {
            case 'X': case 'Y': case 'Z': case 'A': case 'B': case 'C': case 'U': case 'V': case 'W':
                if (!w.foreignAxis) w.foreignAxis = c;
                break;
            case 'M': readM(word, options, w, r); break;
            case 'F': w.F = &word; r.feedWord = i; break;
            case 'H': w.H = &word; break;
            case 'T': w.T = &word; break;
            case 'P': w.P = &word; break;
            case 'L': w.L = &word; break;
            case 'O': w.O = &word; break;
            case 'I': case 'J': case 'K':
                w.ijk[c - 'I'] = i;
                w.arcWords = true;
                break;
            case 'R': w.arcWords = true; break;
            default: break;
        }
    }
}

}  // namespace cnccomp::postproc
