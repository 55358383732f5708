// The compute-or-load policy: where the cache lives, the lock that serialises runs of one key,
// and what a run does with a file it cannot use.
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <thread>

#include "cache/cache_file.h"
#include "cache/link_file.h"
#include "scene/scene.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/progress.h"
#include "util/stopwatch.h"

namespace radiosa {

namespace fs = std::filesystem;

fs::path default_cache_dir() {
    const char* env = std::getenv("RADIOSA_CACHE_DIR");
    if (env && *env) return fs::path(env);
    return fs::path("out") / "cache";
}

const char* cache_status_name(CacheStatus s) {
    switch (s) {
        case CacheStatus::Off:
            return "off";
        case CacheStatus::Hit:
            return "hit";
        case CacheStatus::Miss:
            return "miss";
        case CacheStatus::Rebuilt:
            return "rebuilt";
    }
    return "?";
}

namespace {

// An exclusive advisory lock on "<key>.lock" for as long as it lives, so that concurrent runs
// of one scene compute its matrix once: the others wait, then load the file. The holder writes
// its process id into the file; a waiter says after a second who it is waiting for, and gives
// up with an Error after the timeout (a stopped or hung holder). The lock file is opened
// without following links and removed on release. Correctness never depends on the lock:
// files appear only by atomic rename and are fully checked on load, so when the lock cannot be
// had (unwritable directory, a link or special file in its place) concurrent runs merely
// compute twice.
class KeyLock {
public:
    KeyLock(fs::path path, double timeout_s, const WarningSink& warn) : m_path(std::move(path)) {
        m_fd = ::open(m_path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
        struct stat st {};
        if (m_fd >= 0 && (::fstat(m_fd, &st) != 0 || !S_ISREG(st.st_mode))) release_fd();
        if (m_fd < 0) {
            warn("cannot use the lock file " + m_path.string() + " (" +
                 (errno == ELOOP ? std::string("a symbolic link")
                                 : std::string("not a regular file or ") + std::strerror(errno)) +
                 "); going on without it");
            return;
        }
        wait(timeout_s, warn);
        const std::string pid = std::to_string(::getpid()) + "\n";
        // Who holds it, for the message a waiting run prints; failing to write it is harmless.
        if (::ftruncate(m_fd, 0) == 0) (void)!::pwrite(m_fd, pid.data(), pid.size(), 0);
        m_remove = std::make_unique<RemoveOnSignal>(m_path);
    }
    ~KeyLock() {
        if (m_fd < 0) return;
        ::unlink(m_path.c_str());
        m_remove.reset();
        release_fd();  // closing releases the lock
    }
    KeyLock(const KeyLock&) = delete;
    KeyLock& operator=(const KeyLock&) = delete;

private:
    void release_fd() {
        ::close(m_fd);
        m_fd = -1;
    }
    std::string holder() const {
        char buf[32] = {0};
        const ssize_t n = ::pread(m_fd, buf, sizeof buf - 1, 0);
        const long pid = n > 0 ? std::strtol(buf, nullptr, 10) : 0;
        return pid > 0 ? "process " + std::to_string(pid) : "another process";
    }
    void wait(double timeout_s, const WarningSink& warn) {
        const Stopwatch clock;
        bool announced = false;
        while (::flock(m_fd, LOCK_EX | LOCK_NB) != 0) {
            if (errno != EWOULDBLOCK && errno != EINTR) {
                release_fd();
                return;
            }
            const double waited = clock.seconds();
            if (waited >= timeout_s) {
                const std::string who = holder();
                release_fd();
                throw Error(
                    fmt::format("{}: gave up after {:.0f} s waiting for {} computing the same form factors "
                                "(it may be stopped "
                                "or hung); stop it, raise --lock-timeout, or run with --no-cache",
                                m_path.string(), waited, who));
            }
            if (waited >= 1.0 && !announced) {
                warn(fmt::format(
                    "{}: waiting for {} computing the same form factors (giving up after {:.0f} s)",
                    m_path.string(), holder(), timeout_s));
                announced = true;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
    }

    fs::path m_path;
    int m_fd = -1;
    std::unique_ptr<RemoveOnSignal> m_remove;  // a run ended by a signal releases it too
};

// What is cached (the matrix, or the hierarchical links) and how to make, read and write it.
template <class T>
struct CacheJob {
    const char* extension;  // of the file name: ".rff", ".rhl"
    const char* what;       // in warnings: "form factors", "hierarchical links"
    CacheKey key;
    std::function<T()> compute;
    std::function<T(const fs::path&)> load;  // throws CacheFileError
    // The sense checks (CacheFileError) and the write (Error).
    std::function<void(const fs::path&, const T&)> store;
};

// One run's use of the cache for one object: what it loaded, computed and wrote, and why.
template <class T>
class CacheRun {
public:
    CacheRun(const CacheJob<T>& job, const WarningSink& warn) : m_job(job), m_warn(warn) {}

    CacheOutcome o;

    T compute() {
        const Stopwatch clock;
        T v = m_job.compute();
        o.compute_s = clock.seconds();
        return v;
    }
    // The object when a file is there and passes every check; records why not otherwise.
    std::optional<T> try_load(const fs::path& path) {
        const Stopwatch clock;
        std::error_code ec;
        if (fs::symlink_status(path, ec).type() == fs::file_type::not_found) return std::nullopt;
        try {
            T v = m_job.load(path);
            o.load_s += clock.seconds();
            return v;
        } catch (const CacheFileError& e) {
            o.load_s += clock.seconds();
            o.reason = e.what();
            return std::nullopt;
        }
    }
    // Computes the object and writes its file, unless it would not pass the load checks itself
    // (a scene declared closed that is not): then it is not stored, with a warning. An
    // unwritable cache is a warning, not an error.
    T compute_and_store(const fs::path& path) {
        o.status = o.reason.empty() ? CacheStatus::Miss : CacheStatus::Rebuilt;
        T v = compute();
        const Stopwatch clock;
        try {
            m_job.store(path, v);
            o.written = true;
        } catch (const CacheFileError& e) {
            m_warn(
                fmt::format("the computed {} fail the cache's sense check ({}); they are used but not "
                            "cached: is the scene really closed?",
                            m_job.what, e.what()));
            if (o.reason.empty()) o.reason = std::string("not written: ") + e.what();
        } catch (const Error& e) {
            m_warn(fmt::format("cannot write the {} cache: {}; the run goes on without it", m_job.what,
                               e.what()));
            if (o.reason.empty()) o.reason = std::string("not written: ") + e.what();
        }
        o.write_s = clock.seconds();
        return v;
    }
    // Computes without storing: the cache directory cannot be made.
    T compute_unstored(const fs::path& dir, const std::error_code& ec) {
        o.status = o.reason.empty() ? CacheStatus::Miss : CacheStatus::Rebuilt;
        const std::string why = "cannot create cache directory " + dir.string() + ": " +
                                (ec ? ec.message() : std::string("not a directory"));
        m_warn(fmt::format("{}; {} are computed but not cached", why, m_job.what));
        if (o.reason.empty()) o.reason = why;
        return compute();
    }

private:
    const CacheJob<T>& m_job;
    const WarningSink& m_warn;
};

fs::path cache_dir(const CacheSettings& settings) {
    return settings.dir.empty() ? default_cache_dir() : settings.dir;
}

template <class T>
T obtain(const CacheJob<T>& job, const FormFactorOptions& options, const CacheSettings& settings,
         const WarningSink& warn, CacheOutcome* outcome) {
    CacheRun<T> run(job, warn);
    const auto done = [&](T v) {
        if (outcome) *outcome = run.o;
        return v;
    };
    if (!settings.enabled) return done(run.compute());
    if (!options.culling) {
        // A timing diagnostic: it must be computed to be timed, and in error-controlled mode
        // (no closed form without the proofs) its matrix is less accurate: never stored.
        run.o.reason = "--no-culling";
        return done(run.compute());
    }
    const fs::path dir = cache_dir(settings);
    const fs::path path = dir / (job.key.hex() + job.extension);
    run.o.key = job.key.hex();
    run.o.file = path.string();

    if (auto v = run.try_load(path)) {
        run.o.status = CacheStatus::Hit;
        return done(std::move(*v));
    }
    if (!run.o.reason.empty()) warn("cache file " + path.string() + ": " + run.o.reason + "; recomputing it");
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir, ec)) return done(run.compute_unstored(dir, ec));

    const Stopwatch waited;
    const KeyLock lock(dir / (job.key.hex() + ".lock"), settings.lock_timeout_s, warn);
    run.o.wait_s = waited.seconds();
    // Another process may have computed it while this one waited for the lock.
    const std::string first_reason = run.o.reason;
    if (auto v = run.try_load(path)) {
        run.o.status = CacheStatus::Hit;
        run.o.reason.clear();
        return done(std::move(*v));
    }
    if (run.o.reason.empty()) run.o.reason = first_reason;
    return done(run.compute_and_store(path));
}

CacheJob<FormFactors> matrix_job(const Scene& scene, const SceneGeometry& geometry,
                                 const FormFactorOptions& options, const ComputeFormFactors& how) {
    const CacheKey key = form_factor_key(scene, options);
    return {".rff",
            "form factors",
            key,
            [&scene, &geometry, &options, &how] {
                return how ? how(scene, geometry, options) : compute_form_factors(geometry, options);
            },
            [&scene, &geometry, &options, key](const fs::path& path) {
                return read_cache_file(path, {key, &geometry, options, scene.closed});
            },
            [&scene, &geometry, &options, key](const fs::path& path, const FormFactors& ff) {
                check_cache_matrix(ff, options, scene.closed);
                write_cache_file(path, key, scene.name, scene.closed, geometry, ff);
            }};
}

}  // namespace

FormFactors obtain_form_factors(const Scene& scene, const SceneGeometry& geometry,
                                const FormFactorOptions& options, const CacheSettings& settings,
                                const WarningSink& warn, CacheOutcome* outcome) {
    return obtain(matrix_job(scene, geometry, options, settings.compute), options, settings, warn, outcome);
}

Hierarchy obtain_hierarchy(const Scene& scene, const SceneGeometry& geometry,
                           const FormFactorOptions& options, const CacheSettings& settings,
                           const WarningSink& warn, CacheOutcome* outcome) {
    const CacheKey key = hierarchy_key(scene, options);
    const CacheJob<Hierarchy> job{".rhl",
                                  "hierarchical links",
                                  key,
                                  [&] {
                                      const long long n = geometry.patch_count();
                                      ProgressBar bar(settings.progress, "links", n * (n + 1) / 2);
                                      return build_hierarchy(geometry, hierarchy_options(options), options,
                                                             [&bar](long long pairs) { bar.add(pairs); });
                                  },
                                  [&](const fs::path& path) {
                                      return read_link_file(path, {key, &geometry, options, scene.closed});
                                  },
                                  [&](const fs::path& path, const Hierarchy& h) {
                                      check_cache_links(h, options, scene.closed);
                                      write_link_file(path, key, scene.name, scene.closed, geometry, options,
                                                      h);
                                  }};
    return obtain(job, options, settings, warn, outcome);
}

std::optional<FormFactors> find_cached_form_factors(const Scene& scene, const SceneGeometry& geometry,
                                                    const FormFactorOptions& options,
                                                    const CacheSettings& settings, CacheOutcome* outcome) {
    const CacheJob<FormFactors> job = matrix_job(scene, geometry, options, settings.compute);
    CacheRun<FormFactors> run(job, [](const std::string&) {});
    std::optional<FormFactors> ff;
    if (settings.enabled && options.culling) {
        const fs::path path = cache_dir(settings) / (job.key.hex() + job.extension);
        run.o.key = job.key.hex();
        run.o.file = path.string();
        ff = run.try_load(path);
        if (ff) run.o.status = CacheStatus::Hit;
    }
    if (outcome) *outcome = run.o;
    return ff;
}

}  // namespace radiosa
