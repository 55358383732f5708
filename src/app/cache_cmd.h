#pragma once
// `radiosa cache list|verify|clear`: inspect and maintain a form-factor cache directory.
#include <filesystem>
#include <ostream>

namespace radiosa {

// Each prints to `out`; verify returns false when any cache file is bad.
void cache_list(const std::filesystem::path& dir, std::ostream& out);
bool cache_verify(const std::filesystem::path& dir, std::ostream& out);
void cache_clear(const std::filesystem::path& dir, std::ostream& out);

}  // namespace radiosa
