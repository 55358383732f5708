#pragma once
// The frames of a sequence across the ranks of an MPI job. Rank 0 has planned the sequence
// and solved every state it needs; it shares the result (the radiosities of each state and
// the camera of each frame to render) and the ranks render frames as they become free
// (task_farm.h), rank 0 too. Rank 0 puts the frames back in order and hands each, in order, to
// `emit`; frames that arrive early wait, at most `window` of them, so memory stays bounded.
// A frame is rendered exactly as one process renders it: the output is identical.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "distribute/cluster.h"
#include "render/image.h"
#include "render/raycast.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace radiosa {

class SceneGeometry;

struct FrameOrder {
    std::string scene_path;
    int threads = 0;
    RenderOptions render;
    struct State {
        std::vector<Rgb> B, E;  // a solution and the emission it was solved for
    };
    std::vector<State> states;
    struct Frame {
        int frame = 0;  // the sequence's frame number
        CameraDesc camera;
        int state = 0;
    };
    std::vector<Frame> frames;  // the frames to render, in order (copies are not sent)
};

struct RenderedFrame {
    std::shared_ptr<const Image> image;
    int rank = 0;
    double render_s = 0.0;
};

// Rank 0. `emit(k, frame)` runs once per entry of order.frames, in order, one at a time.
void render_frames_across(Cluster& cluster, const Scene& scene, const SceneGeometry& geometry,
                          const FrameOrder& order, const std::function<void(int, RenderedFrame)>& emit,
                          int window);

// A worker rank's side of a frames order (worker.cpp).
void serve_frames(Cluster& cluster, const Bytes& order);

}  // namespace radiosa
