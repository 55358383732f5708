#pragma once
// Part of the encode plugin: libav's error codes as radiosa errors, for every libav caller.
#include <cstdint>
extern "C" {
#include <libavutil/error.h>
}

#include <string>

#include "util/error.h"

namespace radiosa::media {

inline std::string av_message(int code) {
    char buf[AV_ERROR_MAX_STRING_SIZE] = {0};
    av_strerror(code, buf, sizeof buf);
    return buf;
}

// Throws Error naming the file and the call when a libav call returned a negative status.
inline int av_check(int status, const char* call, const std::string& path) {
    if (status < 0) throw Error(path + ": " + call + " failed: " + av_message(status));
    return status;
}

}  // namespace radiosa::media
