// The capture's writer: finished frames are turned into EXR layers (and a CSV and a PNG preview
// when asked), encoded and written atomically on a thread of their own, in frame order, while
// the next frames render. A bounded queue keeps memory to a few frames.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "capture_options.h"
#include "sim/flow_textures.h"
#include "sim/particles.h"
#include "sim/status.h"
#include "siviflow/renderer.h"

namespace siviflow {

// A finished frame copied out of its readback buffers, so that the buffers can take the next
// frame while this one is encoded and written.
struct FinishedFrame {
  uint32_t frame = 0;
  Camera camera;
  std::vector<uint16_t> color_halves;
  std::vector<float> window_depth;
  std::vector<float> water_mask;
  std::vector<std::byte> flow_texture;  // as uploaded: shaders/shared.h FlowTexel per texel
  std::vector<float> normal;            // RGBA per pixel
  std::vector<float> reflection;        // RGBA per pixel
  std::vector<float> foam;
  std::vector<Particle> particles;
};

class FrameWriter {
 public:
  // Frames waiting to be written at most: push() waits while this many are queued.
  static constexpr size_t kQueueDepth = 2;

  // `layout` is the renderer's flow texture layout (fixed for the capture); `on_written` runs on
  // the writer's thread after each frame, with the count written so far.
  FrameWriter(const CaptureOptions& options, const FlowTextureLayout& layout,
              std::function<void(uint32_t)> on_written);
  // Writes what is queued, then stops the thread.
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Lets OpenEXR compress on every core (process-wide; the capture tool owns its process).
  static Status start_encoding_threads();

  // Queues `frame`, waiting for room; the writer's first failure instead, after which nothing
  // more is written.
  Status push(FinishedFrame frame);
  // Waits until every queued frame is written; the first failure.
  Status finish();

 private:
  void loop();
  Status write(const FinishedFrame& finished);
  // Each texel of the flow texture, decoded once: its flow and its particle slot.
  void decode_flow_texture(const std::vector<std::byte>& flow_texture);
  Status write_particles_csv(const FinishedFrame& finished, const std::string& path) const;

  const CaptureOptions options_;
  const FlowTextureLayout layout_;
  const std::function<void(uint32_t)> on_written_;
  const std::vector<uint32_t> texel_column_;  // the flow texel column under each pixel column
  // The writer's scratch planes, reused from frame to frame.
  std::vector<float> rgba_;  // the preview's
  std::vector<float> depth_;
  std::vector<float> flow_[3];
  std::vector<float> particle_id_;
  std::vector<glm::vec3> texel_flow_;
  std::vector<uint32_t> texel_slot_;

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<FinishedFrame> queue_;  // guarded by mutex_, with the three below
  bool writing_ = false;             // a frame taken from the queue is being written
  bool stop_ = false;
  Status failure_;
  uint32_t written_ = 0;  // the writer's own
  std::thread thread_;    // last: starts once the members it uses exist
};

}  // namespace siviflow
