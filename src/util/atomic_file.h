#pragma once
// Outputs are written under a temporary sibling name and renamed into place when complete,
// so a failed or killed run never leaves a half-written file under the final name. A run ended
// by SIGTERM, SIGINT or SIGHUP (mpirun aborting a job, Ctrl-C) also removes its temporaries.
//
// The temporary file is created exclusively (O_CREAT | O_EXCL | O_NOFOLLOW) under a name with
// a random part, in the final file's directory: a link planted at a predictable name is never
// followed, and a file that already exists is never written through. Writers that can, write
// through fd(); writers that open by name (OpenImageIO, libav) open the file this created.
#include <filesystem>
#include <string>

namespace radiosa {

class AtomicFile {
public:
    // `final_path` keeps its extension on the temporary name ("a.png" -> "a.tmp<pid>-<hex>.png")
    // so writers that pick a format from the extension still work. Throws Error when the
    // temporary file cannot be created.
    explicit AtomicFile(std::filesystem::path final_path);
    ~AtomicFile();  // removes the temporary file unless commit() succeeded
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    const std::filesystem::path& temp_path() const { return m_temp; }
    const std::filesystem::path& final_path() const { return m_final; }
    // The open temporary file (write-only), or -1 after close_fd().
    int fd() const { return m_fd; }
    // Writes all of `data` through fd(); throws Error naming the file on failure.
    void write_all(const void* data, std::size_t size);
    // Flushes to disk (fsync) and closes fd(); throws Error on failure. commit() calls it.
    void close_fd(bool sync = true);
    // Renames the temporary file to the final name; throws Error on failure.
    void commit();

private:
    std::filesystem::path m_final;
    std::filesystem::path m_temp;
    int m_fd = -1;
    int m_slot = -1;  // in the list a signal handler cleans up
    bool m_committed = false;
};

// While it lives, `path` is removed if SIGTERM, SIGINT or SIGHUP ends the process (AtomicFile's
// temporaries use the same list; so does the cache's lock file).
class RemoveOnSignal {
public:
    explicit RemoveOnSignal(const std::filesystem::path& path);
    ~RemoveOnSignal();
    RemoveOnSignal(const RemoveOnSignal&) = delete;
    RemoveOnSignal& operator=(const RemoveOnSignal&) = delete;

private:
    int m_slot;
};

// Fails early, with a message naming the path, when an output cannot be written there:
// the directory is missing or not writable, or the path is a directory.
void check_output_path(const std::filesystem::path& path);

// Writes `text` to `path` atomically.
void write_text_file(const std::filesystem::path& path, const std::string& text);

}  // namespace radiosa
