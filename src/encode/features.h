#pragma once
// What this build can write. RADIOSA_VIDEO (CMake option, default ON) links FFmpeg's libav for
// H.264 video (.mp4) and the palette outputs (.gif, indexed .png); a build without it writes
// stills and numbered true-colour frames through OpenImageIO only, and refuses the others
// before any work with a message that says how to get them.
#ifndef RADIOSA_HAS_VIDEO
#error "RADIOSA_HAS_VIDEO is set by CMake (option RADIOSA_VIDEO) on radiosa_lib and its users"
#endif

namespace radiosa {

inline constexpr bool kHasVideo = RADIOSA_HAS_VIDEO != 0;

// The message every libav-only output gives in a build without it.
inline constexpr const char* kNoVideoMessage =
    "this build of radiosa has no video or palette encoder (configured with -DRADIOSA_VIDEO=OFF): write "
    "numbered "
    "images such as out/frames/%04d.png, or rebuild with -DRADIOSA_VIDEO=ON (needs libavcodec-dev, "
    "libavformat-dev, libswscale-dev)";

}  // namespace radiosa
