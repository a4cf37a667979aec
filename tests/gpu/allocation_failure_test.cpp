// Allocation failure injected into create, update and record: each returns a status that says
// so (no exception leaves the library, no crash), the log callback hears it, the renderer stays
// destroyable (the fixture's validation layer reports any Vulkan object left behind) and, after
// a failed update or record, renders the next frame.
//
// The injection replaces the global operator new of this test: it fails the Nth allocation made
// from this executable's own code (the library and the standard templates instantiated in it),
// never one of the validation layer's or the driver's, whose C frames must not see exceptions.
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render_frames.h"

extern "C" char __executable_start;  // the bounds of this executable's code (GNU ld)
extern "C" char etext;

namespace {

long g_countdown = -1;  // allocations from our code left before one fails; negative: none fails
long g_failures = 0;

bool from_this_executable(const void* caller) {
  return caller >= static_cast<const void*>(&__executable_start) &&
         caller < static_cast<const void*>(&etext);
}

void* allocate(std::size_t size, const void* caller) {
  if (g_countdown >= 0 && from_this_executable(caller) && g_countdown-- == 0) {
    ++g_failures;
    throw std::bad_alloc();
  }
  void* p = std::malloc(size == 0 ? 1 : size);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

}  // namespace

void* operator new(std::size_t size) { return allocate(size, __builtin_return_address(0)); }
void* operator new[](std::size_t size) { return allocate(size, __builtin_return_address(0)); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// The nothrow forms too (std::stable_sort's buffer): every new of this executable is a malloc,
// so that every delete here frees what its new allocated.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return std::malloc(size == 0 ? 1 : size);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace siviflow::testing {
namespace {

struct LogTally {
  int errors = 0;
  std::string last;
};

void tally(LogLevel level, const char* message, void* user) {
  auto* log = static_cast<LogTally*>(user);
  if (level == LogLevel::kError) ++log->errors;
  log->last = message;
}

// Fails allocation `n` (from our code) of whatever runs until disarm().
void arm(long n) { g_countdown = n; }
void disarm() { g_countdown = -1; }

// 0, 1, 2, 3, 5, 8, ...: early failures densely, later ones sparsely.
std::vector<long> failure_points(long limit) {
  std::vector<long> points;
  for (long n = 0; n < limit; n = n < 3 ? n + 1 : n + n / 2) points.push_back(n);
  return points;
}

class AllocationFailureTest : public RenderTest {
 protected:
  void TearDown() override {
    disarm();
    RenderTest::TearDown();
  }
  LogTally log_;
  CreateInfo logged_info() {
    CreateInfo info = make_create_info(kWidth, kHeight);
    info.log = &tally;
    info.log_user = &log_;
    return info;
  }
};

void expect_out_of_memory(const Status& status, const char* call, long n) {
  EXPECT_EQ(status.code(), VK_ERROR_OUT_OF_HOST_MEMORY) << call << " failing allocation " << n
                                                        << ": " << status.message();
  EXPECT_EQ(status.message().rfind("siviflow::Renderer: ", 0), 0u) << status.message();
}

TEST_F(AllocationFailureTest, CreateFailsCleanlyAtEveryPoint) {
  // The world first, without injection: the renderer's create is what is tested.
  ASSERT_TRUE(create_renderer(logged_info()).ok());
  CreateInfo info = logged_info();
  info.reflection = &World::draw_reflection;
  info.reflection_user = world_.get();
  long failed = 0;
  for (const long n : failure_points(1'000'000)) {
    renderer_.reset();
    g_failures = 0;
    arm(n);
    const Status status = Renderer::create(info, &renderer_);
    disarm();
    if (g_failures == 0) {  // create made fewer than n allocations: it succeeded untouched
      ASSERT_TRUE(status.ok()) << status.message();
      break;
    }
    ++failed;
    expect_out_of_memory(status, "create", n);
    EXPECT_EQ(renderer_, nullptr);
    EXPECT_EQ(log_.last, status.message()) << "the log heard it";
  }
  EXPECT_GT(failed, 10) << "create allocates; each failure point was exercised";
  ASSERT_NE(renderer_, nullptr);
  EXPECT_EQ(render(0, 1).size(), 1u) << "a create after the failures renders";
}

class FrameAfterFailuresTest : public AllocationFailureTest {
 protected:
  void SetUp() override {
    AllocationFailureTest::SetUp();
    ASSERT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets_).ok());
  }

  // A fresh renderer that has rendered frame 0.
  void start() {
    ASSERT_TRUE(create_renderer(logged_info()).ok());
    ASSERT_EQ(render(0, 1).size(), 1u);
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
      ASSERT_TRUE(context_->create_readback_buffer(
          renderer_->readback_bytes(static_cast<ReadbackImage>(i)), &readback_[i]).ok());
      buffers_.buffers[i] = readback_[i].buffer;
    }
  }

  // One frame at `time` (default frame 1's) and its view, its record failing allocation `n`
  // (negative: none). A failed record's command buffer is discarded, as a host would: the next
  // begin_slot resets it.
  Status frame(long n, bool* failed, double time = 1.0 / 30.0) {
    const View view = camera_view(world_->scene_camera(time), {kWidth, kHeight});
    SIVIFLOW_TRY(renderer_->begin_frame(0));
    SIVIFLOW_TRY(renderer_->update(view, time));
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    SIVIFLOW_TRY(context_->begin_slot(0, &cmd));
    g_failures = 0;
    arm(n);
    const Status status =
        record_world_and_water(cmd, 0, *world_, *renderer_, view, time, buffers_, &targets_);
    disarm();
    // A failure that hit the host's own code (its validation message callback, called from
    // inside the layer) may be absorbed there: then the frame is whole and is submitted.
    *failed = !status.ok();
    if (*failed) {
      EXPECT_GT(g_failures, 0) << "a failure without an injected one: " << status.message();
      // The failure may have hit the world before the water recorded: the host drops the frame.
      EXPECT_TRUE(renderer_->abandon_frame().ok());
      return status;
    }
    SIVIFLOW_TRY(context_->end_slot_and_submit(0));
    return context_->wait_slot(0);
  }

  std::vector<float> colour() const {
    std::vector<float> rgba(size_t{kWidth} * kHeight * 4);
    const auto* halves = static_cast<const uint16_t*>(readback_[0].data);
    for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = glm::unpackHalf1x16(halves[i]);
    return rgba;
  }

  HostTargets targets_;
  HostBuffer readback_[kReadbackImageCount];
  ReadbackTargets buffers_;
};

TEST_F(FrameAfterFailuresTest, FailedUpdateReportsAndTheNextFrameRenders) {
  start();
  // Two seconds on: the boulder rolling in from the bank re-solves the flow, and the camera has
  // moved far enough that new particles fill the view, so the update allocates.
  const double time = 2.0;
  const View view = camera_view(world_->scene_camera(time), {kWidth, kHeight});
  long failures = 0;
  for (const long n : failure_points(100'000)) {
    ASSERT_TRUE(renderer_->begin_frame(0).ok());
    g_failures = 0;
    arm(n);
    const Status status = renderer_->update(view, time);
    disarm();
    if (g_failures == 0) {
      ASSERT_TRUE(status.ok()) << status.message();
      ASSERT_TRUE(renderer_->abandon_frame().ok());  // the host renders the next time instead
      break;
    }
    ++failures;
    expect_out_of_memory(status, "update", n);
  }
  EXPECT_GT(failures, 0) << "an update that re-solves the flow allocates";
  EXPECT_EQ(log_.errors, failures) << "each failure reached the log";
  bool failed = false;
  const Status status = frame(-1, &failed, time + 1.0 / 30.0);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::vector<float> rgba = colour();
  size_t water = 0;
  const auto* mask = static_cast<const float*>(readback_[2].data);
  for (size_t i = 0; i < size_t{kWidth} * kHeight; ++i) water += mask[i] == 1.0f ? 1 : 0;
  EXPECT_GT(water, 1000u) << "the frame after the failures shows the river";
}

TEST_F(FrameAfterFailuresTest, FailedRecordLeavesNoTraceInTheNextFrame) {
  start();
  std::vector<bool> submitted;  // per attempt: whether its frame was recorded whole
  long failures = 0;
  for (const long n : failure_points(100'000)) {
    bool failed = false;
    const Status status = frame(n, &failed);
    submitted.push_back(!failed);
    if (failed) {
      ++failures;
      continue;
    }
    ASSERT_TRUE(status.ok()) << status.message();
    if (g_failures == 0) break;  // past the last allocation: the frame is done
  }
  EXPECT_GT(failures, 3) << "recording allocates";
  const std::vector<float> after_failures = colour();
  // The same calls without injection: the failed attempts as frames updated but never submitted.
  start();
  for (const bool whole : submitted) {
    if (whole) {
      bool failed = false;
      ASSERT_TRUE(frame(-1, &failed).ok());
      continue;
    }
    const double time = 1.0 / 30.0;
    ASSERT_TRUE(renderer_->begin_frame(0).ok());
    ASSERT_TRUE(renderer_->update(camera_view(world_->scene_camera(time), {kWidth, kHeight}), time).ok());
    ASSERT_TRUE(renderer_->abandon_frame().ok());
  }
  const std::vector<float> reference = colour();
  size_t differing = 0;
  for (size_t i = 0; i < reference.size(); ++i) differing += after_failures[i] != reference[i] ? 1 : 0;
  EXPECT_EQ(differing, 0u) << "a failed record changed nothing the next frame depends on";
}

}  // namespace
}  // namespace siviflow::testing
