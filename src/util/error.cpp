#include "util/error.h"

namespace radiosa {

std::string FileLoc::to_string() const {
    std::string s = file;
    if (line > 0) {
        s.append(":").append(std::to_string(line));
        if (col > 0) s.append(":").append(std::to_string(col));
    }
    return s;
}

Error::Error(std::string message) : std::runtime_error(message), m_message(std::move(message)) {}

Error::Error(FileLoc loc, std::string message)
    : std::runtime_error(loc.to_string() + ": " + message),
      m_loc(std::move(loc)),
      m_message(std::move(message)) {}

}  // namespace radiosa
