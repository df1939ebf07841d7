#include "cnccomp/io/text_util.hpp"

#include <algorithm>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <ostream>
#include <random>
#include <streambuf>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::io {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r' || s.front() == '\n')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) s.remove_suffix(1);
    return s;
}

std::optional<double> parseNumber(std::string_view s) {
    s = trim(s);
    if (s.empty()) return std::nullopt;
    if (s == "inf" || s == "+inf") return HUGE_VAL;
    if (s == "-inf") return -HUGE_VAL;
    if (s.front() == '+') s.remove_prefix(1);
    double v = 0.0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size() || std::isnan(v)) return std::nullopt;
    return v;
}

std::vector<std::string> commaItems(std::string_view text) {
    std::vector<std::string> out;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t end = std::min(text.find(',', pos), text.size());
        const std::string_view item = trim(text.substr(pos, end - pos));
        if (!item.empty()) out.emplace_back(item);
        pos = end + 1;
    }
    return out;
}

void refuseToOverwrite(const std::string& output, std::span<const std::string> inputs) {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const std::string& in : inputs) {
        if (in.empty()) continue;
        if (fs::exists(output, ec) && fs::exists(in, ec) && fs::equivalent(output, in, ec))
            throw InputError(output, 0, fmt::format("refusing to overwrite the input file '{}'", in));
    }
}

namespace {

namespace fs = std::filesystem;

/// What lstat says about a path, without following a final link: 0 absent, else st_mode.
mode_t linkMode(const std::string& p) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) return 0;
    return st.st_mode;
}

const char* kindOf(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

std::string randomSuffix() {
    static constexpr char kAlphabet[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    std::random_device rd;  // getrandom(2) on Linux: unpredictable
    std::string s;
    for (int i = 0; i < 3; ++i) {
        uint32_t v = rd();
        for (int k = 0; k < 4; ++k, v >>= 8) s.push_back(kAlphabet[(v & 0xff) % 62]);
    }
    return s;
}

}  // namespace

/// An output stream buffer over a file descriptor (no allocation per write, EINTR retried). Outside the anonymous
/// namespace: AtomicFile::Impl, which has external linkage, holds one.
class FdBuf : public std::streambuf {
public:
    explicit FdBuf(int fd) : fd_(fd), buf_(size_t{1} << 16) { setp(buf_.data(), buf_.data() + buf_.size()); }
    bool failed() const { return failed_; }
    int error() const { return error_; }

protected:
    int_type overflow(int_type c) override {
        if (!drain()) return traits_type::eof();
        if (!traits_type::eq_int_type(c, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(c);
            pbump(1);
        }
        return traits_type::not_eof(c);
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        if (n >= static_cast<std::streamsize>(buf_.size())) {
            if (!drain() || !writeAll(s, static_cast<size_t>(n))) return 0;
            return n;
        }
        return std::streambuf::xsputn(s, n);
    }
    int sync() override { return drain() ? 0 : -1; }

private:
    bool writeAll(const char* p, size_t n) {
        while (n > 0 && !failed_) {
            const ssize_t w = ::write(fd_, p, n);
            if (w < 0) {
                if (errno == EINTR) continue;
                failed_ = true;
                error_ = errno;
                break;
            }
            p += w;
            n -= static_cast<size_t>(w);
        }
        return !failed_;
    }
    bool drain() {
        const size_t n = static_cast<size_t>(pptr() - pbase());
        const bool ok = writeAll(pbase(), n);
        setp(buf_.data(), buf_.data() + buf_.size());
        return ok;
    }
    int fd_;
    std::vector<char> buf_;
    bool failed_ = false;
    int error_ = 0;
};

std::string checkOutputPath(const std::string& path) {
    if (path.empty()) throw InputError(path, 0, "the output path is empty");
    std::string target = path;
    // Follow symbolic links to the file they name, so that the link stays and its target is replaced.
    for (int hops = 0;; ++hops) {
        const mode_t m = linkMode(target);
        if (!S_ISLNK(m)) break;
        if (hops >= 40) throw InputError(path, 0, "too many levels of symbolic links");
        std::error_code ec;
        const fs::path link = fs::read_symlink(target, ec);
        if (ec) throw InputError(path, 0, fmt::format("cannot read the symbolic link: {}", ec.message()));
        target = (link.is_absolute() ? link : fs::path(target).parent_path() / link).string();
    }
    const mode_t m = linkMode(target);
    if (m != 0 && !S_ISREG(m))
        throw InputError(path, 0,
                         fmt::format("the output is {}; give the path of a regular file to write (it is never replaced "
                                     "by a file)",
                                     kindOf(m)));
    if (m == 0 && !target.empty() && target.back() == '/')
        throw InputError(path, 0, "the output path names a folder; give a file name");
    const fs::path parent = fs::path(target).has_parent_path() ? fs::path(target).parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(parent, ec))
        throw InputError(path, 0, fmt::format("the output folder '{}' does not exist", parent.string()));
    return target;
}

struct AtomicFile::Impl {
    int fd = -1;
    std::unique_ptr<FdBuf> buf;
    std::unique_ptr<std::ostream> out;
};

AtomicFile::AtomicFile(const std::string& path) : impl_(std::make_unique<Impl>()), path_(path) {
    target_ = checkOutputPath(path);
    const fs::path t(target_);
    const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
    const std::string base = t.filename().string();
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::string name = (dir / ("." + base + "." + randomSuffix() + ".tmp")).string();
        const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
        if (fd >= 0) {
            impl_->fd = fd;
            tmp_ = name;
            break;
        }
        if (errno != EEXIST)
            throw InputError(path, 0, fmt::format("cannot create a temporary file in '{}': {}", dir.string(),
                                                  std::strerror(errno)));
    }
    if (impl_->fd < 0) throw InputError(path, 0, "cannot create a temporary file (no free name)");
    impl_->buf = std::make_unique<FdBuf>(impl_->fd);
    impl_->out = std::make_unique<std::ostream>(impl_->buf.get());
}

AtomicFile::~AtomicFile() {
    if (impl_->fd >= 0) ::close(impl_->fd);
    if (!committed_ && !tmp_.empty()) ::unlink(tmp_.c_str());
}

std::ostream& AtomicFile::stream() { return *impl_->out; }

void AtomicFile::close() {
    if (closed_) return;
    impl_->out->flush();
    if (!*impl_->out || impl_->buf->failed())
        throw InputError(path_, 0, fmt::format("write failed: {}", std::strerror(impl_->buf->error() ? impl_->buf->error() : EIO)));
    struct stat st {};
    if (::stat(target_.c_str(), &st) == 0) {
        // Checked again just before the rename: the target may have changed while the data were written.
        if (!S_ISREG(st.st_mode))
            throw InputError(path_, 0, fmt::format("the output became {} while writing; not replaced", kindOf(st.st_mode)));
        ::fchmod(impl_->fd, st.st_mode & 07777);
    }
    const int rc = ::close(impl_->fd);
    impl_->fd = -1;
    if (rc != 0) throw InputError(path_, 0, fmt::format("write failed: {}", std::strerror(errno)));
    closed_ = true;
}

void AtomicFile::commit() {
    close();
    if (::rename(tmp_.c_str(), target_.c_str()) != 0)
        throw InputError(path_, 0, fmt::format("cannot rename the temporary file onto the output: {}", std::strerror(errno)));
    committed_ = true;
}

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
    AtomicFile file(path);
    write(file.stream());
    file.commit();
}

}  // namespace cnccomp::io
