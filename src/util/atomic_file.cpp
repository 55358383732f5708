#include "util/atomic_file.h"

#include <unistd.h>

#include <fstream>
#include <system_error>

#include "util/error.h"

namespace radiosa {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path final_path) : m_final(std::move(final_path)) {
    fs::path name = m_final.stem();
    name += ".tmp" + std::to_string(::getpid());
    name += m_final.extension();
    m_temp = m_final.parent_path() / name;
}

AtomicFile::~AtomicFile() {
    if (!m_committed) {
        std::error_code ec;
        fs::remove(m_temp, ec);
    }
}

void AtomicFile::commit() {
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
    {
        std::ofstream out(file.temp_path(), std::ios::binary);
        out << text;
        out.flush();
        if (!out) throw Error(path.string() + ": write failed (disk full?)");
    }
    file.commit();
}

}  // namespace radiosa
