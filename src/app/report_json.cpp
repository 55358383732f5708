#include "app/report_json.h"

#include <cstdio>

namespace radiosa {

nlohmann::json cache_outcome_json(const CacheOutcome& c) {
    using nlohmann::json;
    auto str_or_null = [](const std::string& s) { return s.empty() ? json(nullptr) : json(s); };
    return {{"status", cache_status_name(c.status)},
            {"reason", str_or_null(c.reason)},
            {"file", str_or_null(c.file)},
            {"key", str_or_null(c.key)},
            {"written", c.written},
            {"load_s", c.load_s},
            {"compute_s", c.compute_s},
            {"write_s", c.write_s},
            {"wait_s", c.wait_s}};
}

std::string cache_outcome_summary(const CacheOutcome& c) {
    char buf[160];
    std::string s = cache_status_name(c.status);
    switch (c.status) {
        case CacheStatus::Off: return s + " (--no-cache)";
        case CacheStatus::Hit:
            std::snprintf(buf, sizeof buf, " %s (loaded in %.3f s)", c.file.c_str(), c.load_s);
            return s + buf;
        case CacheStatus::Rebuilt:
        case CacheStatus::Miss:
            std::snprintf(buf, sizeof buf, " (computed in %.3f s%s)", c.compute_s,
                          c.written ? ", written" : ", not written");
            s += buf;
            if (c.written) s += " " + c.file;
            if (!c.reason.empty()) s += "; " + c.reason;
            return s;
    }
    return s;
}

}  // namespace radiosa
