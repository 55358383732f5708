#pragma once
// The process's peak resident memory so far (Linux: getrusage's ru_maxrss), in MB.
#include <sys/resource.h>

namespace radiosa {

inline double peak_memory_mb() {
    rusage u{};
    if (getrusage(RUSAGE_SELF, &u) != 0) return 0.0;
    return static_cast<double>(u.ru_maxrss) / 1024.0;  // ru_maxrss is in kB on Linux
}

}  // namespace radiosa
