// Shared by the libFuzzer targets of the file readers (machine XML, plan XML, deviation CSV, instrument files,
// Klartext): the readers take a path, so each input is written to a scratch file of the fuzzing process; a reader may
// refuse an input only with InputError or ModelError (what the CLI reports as bad input, exit 2). Anything else — a
// crash, a sanitizer report, another exception escaping (std::out_of_range, std::bad_alloc …) — is a finding: libFuzzer
// stops, writes the input to its artifact prefix and the ctest entry fails.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>

#include "cnccomp/error.hpp"

namespace cnccomp::fuzz {

/// Writes the input to TMPDIR/cnccomp-fuzz-<pid><suffix> (one file per process, rewritten for every input).
inline std::string writeInput(const uint8_t* data, size_t size, const char* suffix) {
    const char* dir = std::getenv("TMPDIR");
    const std::string path = std::string(dir && *dir ? dir : "/tmp") + "/cnccomp-fuzz-" + std::to_string(::getpid()) + suffix;
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    f.close();
    if (!f) std::abort();
    return path;
}

/// Runs `read`; InputError and ModelError are the reader's accepted ways to refuse. Any other exception aborts.
template <class F>
void expectOnlyInputErrors(F&& read) {
    try {
        read();
    } catch (const InputError&) {
    } catch (const ModelError&) {
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cnccomp fuzz: a reader threw %s instead of InputError: %s\n", typeid(e).name(), e.what());
        std::abort();
    }
}

}  // namespace cnccomp::fuzz
