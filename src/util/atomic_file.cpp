#include "util/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>
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

// Temporary files a signal must not leave behind. SIGTERM (mpirun ending a job because a rank
// failed, or kill), SIGINT (Ctrl-C) and SIGHUP remove every registered temporary file, then end
// the process as the signal would have (or pass the signal on to the handler that was there).
// Slots are fixed buffers so the handler only reads
// memory that stays valid: state 0 free, 1 being written, 2 a path to remove.
constexpr int kTempSlots = 64;
char g_temp_paths[kTempSlots][4096];
std::atomic<int> g_temp_state[kTempSlots];

// The handlers found when this one was installed. The encode plugin carries its own copy of
// this file (and of its slots), so two copies chain: the later one cleans its slots, then
// calls the earlier one, which cleans its own and ends the process.
constexpr int kCleanupSignals[] = {SIGTERM, SIGINT, SIGHUP};
struct sigaction g_previous[3];

void remove_temporaries_and_end(int sig, siginfo_t* info, void* context) {
    for (int k = 0; k < kTempSlots; ++k)
        if (g_temp_state[k].load() == 2) ::unlink(g_temp_paths[k]);
    for (int i = 0; i < 3; ++i) {
        if (kCleanupSignals[i] != sig) continue;
        const struct sigaction& prev = g_previous[i];
        if (prev.sa_flags & SA_SIGINFO) {
            prev.sa_sigaction(sig, info, context);
            return;
        }
        if (prev.sa_handler != SIG_DFL && prev.sa_handler != SIG_IGN) {
            prev.sa_handler(sig);
            return;
        }
    }
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

void install_signal_cleanup() {
    static std::once_flag once;
    std::call_once(once, [] {
        for (int i = 0; i < 3; ++i) {
            // An ignored signal stays ignored; any other handler is chained.
            if (::sigaction(kCleanupSignals[i], nullptr, &g_previous[i]) != 0 ||
                (!(g_previous[i].sa_flags & SA_SIGINFO) && g_previous[i].sa_handler == SIG_IGN))
                continue;
            struct sigaction sa {};
            sa.sa_sigaction = remove_temporaries_and_end;
            sa.sa_flags = SA_SIGINFO;
            sigemptyset(&sa.sa_mask);
            ::sigaction(kCleanupSignals[i], &sa, nullptr);
        }
    });
}

// The slot now holding `path`, or -1 (no slot free, or too long: then a signal may leave it).
int register_temporary(const fs::path& path) {
    install_signal_cleanup();
    const std::string& s = path.native();
    if (s.size() >= sizeof g_temp_paths[0]) return -1;
    for (int k = 0; k < kTempSlots; ++k) {
        int free = 0;
        if (!g_temp_state[k].compare_exchange_strong(free, 1)) continue;
        std::memcpy(g_temp_paths[k], s.c_str(), s.size() + 1);
        g_temp_state[k].store(2);
        return k;
    }
    return -1;
}

void unregister_temporary(int slot) {
    if (slot >= 0) g_temp_state[slot].store(0);
}

}  // namespace

RemoveOnSignal::RemoveOnSignal(const fs::path& path) : m_slot(register_temporary(path)) {}
RemoveOnSignal::~RemoveOnSignal() { unregister_temporary(m_slot); }

AtomicFile::AtomicFile(fs::path final_path) : m_final(std::move(final_path)) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        fs::path name = m_final.stem();
        name += ".tmp" + std::to_string(::getpid()) + "-" + random_hex();
        name += m_final.extension();
        m_temp = m_final.parent_path() / name;
        m_fd = ::open(m_temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (m_fd >= 0) {
            m_slot = register_temporary(m_temp);
            return;
        }
        if (errno != EEXIST)
            throw Error(m_final.string() + ": cannot create temporary file: " + std::strerror(errno));
    }
    throw Error(m_final.string() + ": cannot create a temporary file with a fresh name");
}

AtomicFile::~AtomicFile() {
    unregister_temporary(m_slot);
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
    unregister_temporary(m_slot);
    m_slot = -1;
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
