#include "frame_writer.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <system_error>

#include "siviflow/atomic_file.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"

namespace siviflow {
namespace {

// Runs `step` on `frame`, turning an exception out of it (std::bad_alloc from a plane or a path)
// into an error status, so that a writer's thread stops the capture rather than the process.
template <typename Step>
Status guarded(const char* action, uint32_t frame, Step&& step) noexcept {
  try {
    return step();
  } catch (const std::exception& e) {
    try {
      return Status::error(std::string("cannot ") + action + " " + frame_file_name(frame) + ": " +
                           e.what());
    } catch (...) {
      return Status::error("out of memory");
    }
  }
}

}  // namespace

FrameWriter::FrameWriter(const CaptureOptions& options, const FlowTextureLayout& layout,
                         std::function<void(uint32_t)> on_written)
    : options_(options), on_written_(std::move(on_written)) {
  spares_.reserve(kSpareFrames);
  for (size_t i = 0; i < kEncoders; ++i) {
    encoders_.push_back(std::make_unique<FrameEncoder>(options, layout));
  }
  try {
    for (const std::unique_ptr<FrameEncoder>& encoder : encoders_) {
      threads_.emplace_back([this, encoder = encoder.get()] { encode_loop(encoder); });
    }
  } catch (const std::system_error& e) {  // no thread to be had: push() reports why
    std::lock_guard lock(mutex_);
    failure_ = Status::error(std::string("cannot start an encoding thread: ") + e.what());
  }
  changed_.notify_all();
}

Status FrameWriter::start_encoding_threads() {
  // The GPU side waits on its fences most of a frame with every AOV: OpenEXR compresses the line
  // blocks of a frame on every core meanwhile.
  return set_exr_threads(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

FrameWriter::~FrameWriter() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  for (std::thread& thread : threads_) thread.join();
}

Status FrameWriter::push(FinishedFrame frame) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return !failure_.ok() || queue_.size() + in_hand_ < kEncoders; });
  if (!failure_.ok()) return failure_;
  queue_.emplace_back(next_ticket_++, std::move(frame));
  changed_.notify_all();
  return Status::success();
}

Status FrameWriter::finish() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return !failure_.ok() || (queue_.empty() && in_hand_ == 0); });
  return failure_;
}

FinishedFrame FrameWriter::spare_frame() {
  std::lock_guard lock(mutex_);
  if (spares_.empty()) return {};
  FinishedFrame spare = std::move(spares_.back());
  spares_.pop_back();
  return spare;
}

void FrameWriter::encode_loop(FrameEncoder* encoder) {
  EncodedFrame encoded;  // its buffers reused from frame to frame
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || !failure_.ok() || !queue_.empty(); });
    if (queue_.empty() || !failure_.ok()) return;  // stopped, or nothing more is written
    const uint64_t ticket = queue_.front().first;
    FinishedFrame frame = std::move(queue_.front().second);
    queue_.pop_front();
    ++in_hand_;
    lock.unlock();
    Status status = guarded("encode", frame.frame, [&] {
      const Status encoding = encoder->encode(frame, &encoded);
      if (encoding.ok()) return encoding;
      return Status::error(frame_file_name(frame.frame) + ": " + encoding.message());
    });
    lock.lock();
    // Files are written, and failures reported, in frame order.
    changed_.wait(lock, [&] { return next_write_ == ticket || !failure_.ok(); });
    if (failure_.ok() && status.ok()) {
      lock.unlock();
      status = guarded("write", frame.frame, [&] {
        SIVIFLOW_TRY(write(encoded));
        if (on_written_) on_written_(written_ + 1);  // only this thread writes now
        return Status::success();
      });
      lock.lock();
      if (status.ok()) ++written_;
    }
    if (failure_.ok() && !status.ok()) failure_ = std::move(status);
    if (spares_.size() < kSpareFrames) spares_.push_back(std::move(frame));  // capacity reserved
    ++next_write_;
    --in_hand_;
    changed_.notify_all();
  }
}

Status FrameWriter::write(const EncodedFrame& encoded) const {
  const std::string exr = options_.out_dir + "/" + frame_file_name(encoded.frame);
  const std::string base = exr.substr(0, exr.size() - 4);
  SIVIFLOW_TRY(write_file_atomically(exr, encoded.exr.data(), encoded.exr.size()));
  if (options_.particles_aov) {
    const Status csv = write_file_atomically(base + ".particles.csv", encoded.particles_csv.data(),
                                             encoded.particles_csv.size());
    if (!csv.ok()) {
      std::remove(exr.c_str());  // a frame is its EXR and its CSV, or nothing
      return csv;
    }
  }
  if (options_.preview) {
    SIVIFLOW_TRY(
        write_file_atomically(base + ".png", encoded.preview.data(), encoded.preview.size()));
  }
  return Status::success();
}

}  // namespace siviflow
