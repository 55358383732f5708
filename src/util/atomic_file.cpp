#include "util/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <system_error>

#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;

namespace {

std::string random_hex() {
    static thread_local std::mt19937_64 rng(std::random_device{}() ^
                                            (static_cast<std::uint64_t>(::getpid()) << 32));
    static const char* digits = "0123456789abcdef";
    std::string s;
    std::uint64_t v = rng();
    for (int k = 0; k < 8; ++k, v >>= 4) s += digits[v & 15];
    return s;
}

}  // namespace

AtomicFile::AtomicFile(fs::path final_path) : m_final(std::move(final_path)) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        fs::path name = m_final.stem();
        name += ".tmp" + std::to_string(::getpid()) + "-" + random_hex();
        name += m_final.extension();
        m_temp = m_final.parent_path() / name;
        m_fd = ::open(m_temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (m_fd >= 0) return;
        if (errno != EEXIST)
            throw Error(m_final.string() + ": cannot create temporary file: " + std::strerror(errno));
    }
    throw Error(m_final.string() + ": cannot create a temporary file with a fresh name");
}

AtomicFile::~AtomicFile() {
    if (m_fd >= 0) ::close(m_fd);
    if (!m_committed) {
        std::error_code ec;
        fs::remove(m_temp, ec);
    }
}

void AtomicFile::write_all(const void* data, std::size_t size) {
    const auto* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(m_fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw Error(m_final.string() + ": write failed: " + std::strerror(n < 0 ? errno : ENOSPC));
        p += n;
        size -= static_cast<std::size_t>(n);
    }
}

void AtomicFile::close_fd(bool sync) {
    if (m_fd < 0) return;
    const bool synced = !sync || ::fsync(m_fd) == 0;
    const int saved = errno;
    const bool closed = ::close(m_fd) == 0;
    m_fd = -1;
    if (!synced || !closed)
        throw Error(m_final.string() + ": write failed: " + std::strerror(synced ? errno : saved));
}

void AtomicFile::commit() {
    close_fd(false);
    std::error_code ec;
    fs::rename(m_temp, m_final, ec);
    if (ec) throw Error(m_final.string() + ": cannot move finished output into place: " + ec.message());
    m_committed = true;
}

void check_output_path(const fs::path& path) {
    if (path.empty()) throw Error("output path is empty");
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(path.string() + ": directory '" + dir.string() +
                    "' does not exist (create it or choose another output path)");
    if (fs::is_directory(path, ec)) throw Error(path.string() + ": is a directory; give a file name");
    if (::access(dir.c_str(), W_OK) != 0)
        throw Error(path.string() + ": directory '" + dir.string() + "' is not writable");
}

void write_text_file(const fs::path& path, const std::string& text) {
    check_output_path(path);
    AtomicFile file(path);
    file.write_all(text.data(), text.size());
    file.commit();
}

}  // namespace radiosa
