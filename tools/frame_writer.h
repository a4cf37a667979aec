// The capture's writer: finished frames are encoded on threads of their own while the next frames
// render, and their files written atomically in frame order. A frame is taken only when an
// encoder is free for it, which bounds the memory; the first failure, in frame order, stops the
// writing.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "capture_options.h"
#include "frame_encoder.h"
#include "sim/flow_textures.h"
#include "siviflow/status.h"

namespace siviflow {

class FrameWriter {
 public:
  // Frames encoded at once: one encoder's serial work (its planes, its file writes) overlaps
  // the other's compression on OpenEXR's threads. push() waits while every encoder holds a
  // frame (until that frame's files are written): a queue ahead of them held a frame each, and
  // a frame with every AOV is 34 bytes a pixel (282 MB at 3840x2160), for no more frames a
  // second, since the capture pushes a frame only once it has submitted the next.
  static constexpr size_t kEncoders = 2;
  // Frames kept for their buffers at most: one per place a frame can be (the encoders, the
  // capture's hands).
  static constexpr size_t kSpareFrames = kEncoders + 1;

  // `layout` is the renderer's flow texture layout (fixed for the capture); `on_written` runs on
  // a writer's thread after each frame, with the count written so far.
  FrameWriter(const CaptureOptions& options, const FlowTextureLayout& layout,
              std::function<void(uint32_t)> on_written);
  // Writes what is queued (unless a write failed), then stops the threads.
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Lets OpenEXR compress on every core (process-wide; the capture tool owns its process).
  static Status start_encoding_threads();

  // Hands `frame` to an encoder (frames come in frame order), waiting for one to be free; the
  // writer's first failure instead, after which nothing more is written.
  Status push(FinishedFrame frame);
  // Waits until every queued frame is written; the first failure.
  Status finish();
  // A frame whose buffers an encoded frame left (empty at first): the capture copies the next
  // frame into them, so that the capture allocates nothing per frame once under way.
  FinishedFrame spare_frame();

 private:
  void encode_loop(FrameEncoder* encoder);
  // Writes the frame's files: its EXR, then its CSV (or neither), then its preview.
  Status write(const EncodedFrame& encoded) const;

  const CaptureOptions options_;
  const std::function<void(uint32_t)> on_written_;
  std::vector<std::unique_ptr<FrameEncoder>> encoders_;

  std::mutex mutex_;
  std::condition_variable changed_;
  // Pushed and not yet taken by an encoder (at most the free ones); guarded by mutex_, with those
  // below.
  std::deque<std::pair<uint64_t, FinishedFrame>> queue_;
  std::vector<FinishedFrame> spares_;
  uint64_t next_ticket_ = 0;  // the place in frame order of the next frame pushed
  uint64_t next_write_ = 0;   // whose files are written next
  size_t in_hand_ = 0;        // frames taken from the queue and not yet written or dropped
  bool stop_ = false;
  Status failure_;
  uint32_t written_ = 0;
  std::vector<std::thread> threads_;  // last: start once the members they use exist
};

}  // namespace siviflow
