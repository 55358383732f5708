#pragma once
// Pieces of the JSON run report shared by the commands that write one.
#include <nlohmann/json.hpp>
#include <string>

#include "cache/cache_file.h"

namespace radiosa {

// "form_factor_cache": {status, reason, file, key, load_s, compute_s, write_s, wait_s}
nlohmann::json cache_outcome_json(const CacheOutcome& c);
// One line for stdout, e.g. "hit out/cache/3f...rff (loaded in 0.001 s)".
std::string cache_outcome_summary(const CacheOutcome& c);

}  // namespace radiosa
