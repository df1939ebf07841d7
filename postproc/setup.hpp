#pragma once
// Machine setup a program runs with: work offsets (G54 … G59.3, G54.1 Pn, G500/G505…) and tool lengths,
// given on the command line (--work-offset G54=x,y,z[,a,b,c], --tool-length [Hn=]L) or in a setup file
// with the same entries one per line.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::postproc {

/// Work offset codes as integers: G54 → 540, G59.1 → 591, G54.1 P3 → 100003, Sinumerik G500 → 5000, G505 → 5050.
int offsetCodeOfG(double gValue, int pValue = 0);
/// "G54", "G59.1", "G54.1P3" / "G54.1 P3", "G505"; nullopt when not a work offset name.
std::optional<int> parseOffsetCode(std::string_view name);
std::string offsetCodeName(int code);
/// "M428" / "m428" / "428" → 428; nullopt when not a whole M number 0..99999.
std::optional<int> parseMCode(std::string_view text);

struct WorkOffset {
    int code = 540;
    std::array<double, 6> xyzabc{};  ///< mm (X Y Z) and degrees (A B C), machine units regardless of G20/G21
};

struct Setup {
    std::vector<WorkOffset> offsets;
    std::vector<std::pair<int, double>> toolLengths;  ///< length-offset register (H / tool number) → mm
    double defaultToolLength = 0.0;                   ///< mm: tool point when no G43 is active (or H unknown)
    /// defaultToolLength was given (--tool-length L, a setup file's "tool-length L", or the test program's header):
    /// else it is 0 by assumption, and `cnccomp correct` refuses a rotary move whose correction depends on it.
    bool defaultToolLengthGiven = false;
    bool inchDefault = false;                         ///< units when the program sets none (G20/G21)
    /// Machine positions (mm, deg) of axes until the program commands them (e.g. Y=0 for a lathe program on a
    /// mill-turn machine). Rotary axes not listed are taken at 0; linear axes not listed are unknown.
    std::vector<std::pair<char, double>> assumed;

    const WorkOffset* offset(int code) const;
    std::optional<double> toolLength(int number) const;

    /// "G54=100,0,-300[,a,b,c]". `source` and `line` name the option or setup file in errors.
    void addWorkOffset(std::string_view spec, const std::string& source = "--work-offset", int line = 0);
    /// "120.5" (default length) or "H3=120.5" / "T3=120.5" / "3=120.5".
    void addToolLength(std::string_view spec, const std::string& source = "--tool-length", int line = 0);
    /// "Y=0" or "Y=0,B=90": positions of axes the program has not commanded yet (mm, deg).
    void addAssumed(std::string_view spec, const std::string& source = "--assume", int line = 0);
    /// Setup file: lines "work-offset G54=…", "tool-length H3=…", "assume Y=0", "units inch|mm"; '#' comments.
    /// Throws InputError.
    void readFile(const std::string& path);
    /// LinuxCNC tool table (docs: "Tool Table Format"): one tool a line, "T1 P1 Z12.5 D6 ;comment", words T (tool
    /// number) P (pocket) X Y Z A B C U V W (offsets) D (diameter) I J Q (lathe); the Z offset becomes the length of
    /// tool n for G43 / G43 Hn (LinuxCNC's H is the tool number). Throws InputError naming file and line.
    void readToolTable(const std::string& path);
};

}  // namespace cnccomp::postproc
