#pragma once
// One exception type for bad input, carrying the place in the input file that is wrong.
// Only the command-line front end catches it and prints "error: file:line:col: message".
#include <optional>
#include <stdexcept>
#include <string>

namespace radiosa {

struct FileLoc {
    std::string file;
    int line = 0;  // 1-based; 0 = unknown
    int col = 0;   // 1-based; 0 = unknown
    std::string to_string() const;
};

class Error : public std::runtime_error {
public:
    explicit Error(std::string message);
    Error(FileLoc loc, std::string message);

    const std::optional<FileLoc>& loc() const { return m_loc; }
    const std::string& message() const { return m_message; }

private:
    std::optional<FileLoc> m_loc;
    std::string m_message;
};

}  // namespace radiosa
