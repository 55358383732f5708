#pragma once
#include <ostream>

namespace radiosa {

// The command-line program, callable in-process (tests drive it directly).
// Returns the exit code: 0 success, 1 bad input or unwritable output, 2 internal failure.
int run_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace radiosa
