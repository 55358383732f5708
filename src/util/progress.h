#pragma once
// A progress line for long stages on a terminal: "\r  form factors [######........] 41%  ETA 12 s",
// redrawn at most five times a second, from any number of threads.
#include <atomic>
#include <mutex>
#include <ostream>
#include <string>

#include "util/stopwatch.h"

namespace radiosa {

class ProgressBar {
public:
    // `out` nullptr: a bar that prints nothing. `total` units of work (pairs, rows, ...).
    ProgressBar(std::ostream* out, std::string label, long long total);
    ~ProgressBar();  // ends the line
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    // Adds `n` units done; thread-safe. Redraws when the last drawing is 0.2 s old.
    void add(long long n);

private:
    void draw(long long done);
    std::ostream* m_out;
    std::string m_label;
    long long m_total;
    std::atomic<long long> m_done{0};
    std::mutex m_draw;
    Stopwatch m_clock;
    double m_last_draw = -1.0;
    bool m_drawn = false;
};

}  // namespace radiosa
