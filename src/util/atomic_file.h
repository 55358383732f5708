#pragma once
// Outputs are written under a temporary sibling name and renamed into place when complete,
// so a failed or killed run never leaves a half-written file under the final name.
#include <filesystem>

namespace radiosa {

class AtomicFile {
public:
    // `final_path` keeps its extension on the temporary name ("a.png" -> "a.tmp<pid>.png")
    // so writers that pick a format from the extension still work.
    explicit AtomicFile(std::filesystem::path final_path);
    ~AtomicFile();  // removes the temporary file unless commit() succeeded
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    const std::filesystem::path& temp_path() const { return m_temp; }
    const std::filesystem::path& final_path() const { return m_final; }
    // Renames the temporary file to the final name; throws Error on failure.
    void commit();

private:
    std::filesystem::path m_final;
    std::filesystem::path m_temp;
    bool m_committed = false;
};

// Fails early, with a message naming the path, when an output cannot be written there:
// the directory is missing or not writable, or the path is a directory.
void check_output_path(const std::filesystem::path& path);

// Writes `text` to `path` atomically.
void write_text_file(const std::filesystem::path& path, const std::string& text);

}  // namespace radiosa
