#pragma once
// Where a stage sends one-line warnings (a damaged cache file, a nearly singular system): the
// command line prints them as "warning: ..." on stderr; tests collect them.
#include <functional>
#include <string>

namespace radiosa {

using WarningSink = std::function<void(const std::string&)>;

}  // namespace radiosa
