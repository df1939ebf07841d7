#pragma once
// Headless Chromium for the report tests: load a page or an SVG, take a screenshot, read its pixels back (PNG decoded
// with the system zlib). Chromium is the Debian package `chromium` (tools/deps.sh); tests skip with the reason
// without it.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <dlfcn.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace cnccomp::test {
namespace browser_fs = std::filesystem;

inline const char* chromium() {
    for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
        if (browser_fs::exists(p)) return p;
    return nullptr;
}

/// Loads `file` in headless Chromium, takes a screenshot of w × h px; returns Chromium's log (console messages are
/// logged as "CONSOLE" lines).
inline std::string screenshot(const std::string& file, const std::string& png, int w, int h, const ScratchDir& dir) {
    const std::string profile = dir.file("chromium-profile-" + std::to_string(w) + "x" + std::to_string(h));
    browser_fs::create_directories(profile);
    const std::string log = dir.file("chromium.log");
    const std::string cmd = fmt::format(
        "timeout 180 {} --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking "
        "--disable-component-update --disable-sync --hide-scrollbars --force-device-scale-factor=1 --user-data-dir='{}' "
        "--enable-logging=stderr --v=0 --window-size={},{} --screenshot='{}' 'file://{}' >'{}' 2>&1",
        chromium(), profile, w, h, png, browser_fs::absolute(file).string(), log);
    const int rc = std::system(cmd.c_str());
    EXPECT_EQ(rc, 0) << cmd << "\n" << readText(log);
    return readText(log);
}

/// An RGB(A) picture decoded from a PNG (8-bit, colour type 2 or 6, no interlace), inflated with the system zlib.
struct Picture {
    int w = 0, h = 0, channels = 0;
    std::vector<unsigned char> px;
    std::array<int, 3> at(int x, int y) const {
        const size_t i = (static_cast<size_t>(y) * w + x) * channels;
        return {px[i], px[i + 1], px[i + 2]};
    }
};

inline std::optional<Picture> readPng(const std::string& path, std::string& why) {
    using Uncompress = int (*)(unsigned char*, unsigned long*, const unsigned char*, unsigned long);
    static void* z = dlopen("libz.so.1", RTLD_NOW);
    if (!z) return why = "libz.so.1 not found", std::nullopt;
    const auto uncompress = reinterpret_cast<Uncompress>(dlsym(z, "uncompress"));
    const std::string s = readText(path);
    if (s.size() < 8 || s.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return why = "not a PNG", std::nullopt;
    const auto be32 = [&](size_t i) {
        return (static_cast<unsigned>(static_cast<unsigned char>(s[i])) << 24) | (static_cast<unsigned char>(s[i + 1]) << 16) |
               (static_cast<unsigned char>(s[i + 2]) << 8) | static_cast<unsigned char>(s[i + 3]);
    };
    Picture p;
    std::string idat;
    for (size_t i = 8; i + 8 <= s.size();) {
        const unsigned len = be32(i);
        const std::string type = s.substr(i + 4, 4);
        if (type == "IHDR") {
            p.w = static_cast<int>(be32(i + 8));
            p.h = static_cast<int>(be32(i + 12));
            const int depth = static_cast<unsigned char>(s[i + 16]), colour = static_cast<unsigned char>(s[i + 17]);
            if (depth != 8 || (colour != 2 && colour != 6) || s[i + 20] != 0) return why = "unsupported PNG format", std::nullopt;
            p.channels = colour == 6 ? 4 : 3;
        } else if (type == "IDAT") {
            idat += s.substr(i + 8, len);
        }
        i += 12 + len;
    }
    const size_t stride = static_cast<size_t>(p.w) * p.channels;
    std::vector<unsigned char> raw((stride + 1) * p.h);
    unsigned long n = raw.size();
    if (uncompress(raw.data(), &n, reinterpret_cast<const unsigned char*>(idat.data()), idat.size()) != 0 || n != raw.size())
        return why = "inflate failed", std::nullopt;
    p.px.assign(stride * p.h, 0);
    for (int y = 0; y < p.h; ++y) {  // PNG filters (RFC 2083 section 6)
        const unsigned char f = raw[y * (stride + 1)];
        const unsigned char* in = &raw[y * (stride + 1) + 1];
        unsigned char* out = &p.px[y * stride];
        const unsigned char* up = y > 0 ? &p.px[(y - 1) * stride] : nullptr;
        for (size_t x = 0; x < stride; ++x) {
            const int a = x >= static_cast<size_t>(p.channels) ? out[x - p.channels] : 0, b = up ? up[x] : 0,
                      c = up && x >= static_cast<size_t>(p.channels) ? up[x - p.channels] : 0;
            int v = in[x];
            if (f == 1) v += a;
            else if (f == 2) v += b;
            else if (f == 3) v += (a + b) / 2;
            else if (f == 4) {
                const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
                v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
            }
            out[x] = static_cast<unsigned char>(v & 0xff);
        }
    }
    return p;
}

inline std::array<int, 3> rgb(const char* hex) {
    const unsigned v = static_cast<unsigned>(std::stoul(hex + 1, nullptr, 16));
    return {static_cast<int>(v >> 16), static_cast<int>((v >> 8) & 0xff), static_cast<int>(v & 0xff)};
}

inline bool near(std::array<int, 3> a, std::array<int, 3> b, int tol = 40) {
    return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) <= tol;
}

/// Is there a pixel of `colour` within `r` px of (x, y)?
inline bool colourNear(const Picture& p, double x, double y, const char* colour, int r = 3) {
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
            const int xx = static_cast<int>(std::lround(x)) + dx, yy = static_cast<int>(std::lround(y)) + dy;
            if (xx >= 0 && yy >= 0 && xx < p.w && yy < p.h && near(p.at(xx, yy), rgb(colour))) return true;
        }
    return false;
}

inline long countColour(const Picture& p, const char* colour) {
    long n = 0;
    for (int y = 0; y < p.h; ++y)
        for (int x = 0; x < p.w; ++x) n += near(p.at(x, y), rgb(colour), 24) ? 1 : 0;
    return n;
}

}  // namespace cnccomp::test
