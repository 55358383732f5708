#include "util/progress.h"

#include <fmt/format.h>

#include <algorithm>

namespace radiosa {

ProgressBar::ProgressBar(std::ostream* out, std::string label, long long total)
    : m_out(out), m_label(std::move(label)), m_total(std::max(total, 1LL)) {}

ProgressBar::~ProgressBar() {
    if (!m_out || !m_drawn) return;
    draw(m_done.load());
    *m_out << "\n" << std::flush;
}

void ProgressBar::add(long long n) {
    const long long done = m_done.fetch_add(n) + n;
    if (!m_out) return;
    // One thread draws; the others go on working.
    std::unique_lock lock(m_draw, std::try_to_lock);
    if (!lock.owns_lock() || m_clock.seconds() - m_last_draw < 0.2) return;
    draw(done);
}

void ProgressBar::draw(long long done) {
    const double elapsed = m_clock.seconds();
    m_last_draw = elapsed;
    m_drawn = true;
    const double f = std::clamp(static_cast<double>(done) / static_cast<double>(m_total), 0.0, 1.0);
    const int width = 30, filled = static_cast<int>(f * width);
    const std::string eta = f > 0.0 && f < 1.0 ? fmt::format("  ETA {:.0f} s", elapsed * (1.0 - f) / f) : "";
    *m_out << fmt::format("\r  {} [{}{}] {:3.0f}%  {:.0f} s{} ", m_label, std::string(filled, '#'),
                          std::string(width - filled, '.'), 100.0 * f, elapsed, eta)
           << std::flush;
}

}  // namespace radiosa
