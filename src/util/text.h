#pragma once
// Text from files (scene names, paths, messages quoting them) printed to a terminal: control
// characters and bytes that are not printable are escaped, so a name cannot move the cursor,
// change colours or forge a line of output.
#include <string>
#include <string_view>

namespace radiosa {

inline std::string printable(std::string_view s) {
    static const char* digits = "0123456789abcdef";
    std::string out;
    out.reserve(s.size());
    for (const char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        if (c == '\\') {
            out += "\\\\";
        } else if (c < 0x20 || c == 0x7f) {
            out += "\\x";
            out += digits[c >> 4];
            out += digits[c & 15];
        } else {
            out += ch;  // UTF-8 continuation and lead bytes pass: names may be in any language
        }
    }
    return out;
}

}  // namespace radiosa
