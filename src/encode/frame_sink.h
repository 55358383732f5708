#pragma once
// Part of the encode plugin: the sinks behind make_frame_sink (encode/encode.h).
#include "encode/encode.h"

namespace radiosa::media {

void check_sequence_output(const std::string& path, int width, int height);
std::unique_ptr<FrameSink> make_frame_sink(const std::string& path, int width, int height,
                                           const SinkOptions& options);

}  // namespace radiosa::media
