// A long run in one process: the default scene at 320x180 along its camera path, two frames in
// flight, the shipping path (no readback), under validation. After a warm-up, resident memory
// stays flat (the mean over the last frames within 1 MiB of the mean over the first) and the
// renderer creates no device memory, buffer, image, descriptor pool or set (its staging blocks
// and pools do not grow), and no kind of object adds up. The windows compared are a thousand frames, or a fifth of a shorter
// run. CI runs 1,000 frames; SIVIFLOW_SOAK_FRAMES sets another count (500 at least).
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "device_call_faults.h"
#include "gpu_test.h"
#include "siviflow/host_frame.h"

namespace siviflow::testing {
namespace {

namespace watch = device_call_faults;

constexpr uint32_t kSoakWidth = 320;
constexpr uint32_t kSoakHeight = 180;
constexpr uint32_t kDefaultFrames = 1000;
constexpr uint32_t kWarmUpFrames = 300;  // the caches of the driver and the layer fill up
constexpr double kMiB = 1024.0 * 1024.0;
#ifdef __SANITIZE_ADDRESS__
// AddressSanitizer's quarantine holds freed memory back on purpose: resident memory says nothing
// there, and LeakSanitizer judges the leaks at the end instead.
constexpr bool kResidentJudged = false;
#else
constexpr bool kResidentJudged = true;
#endif

// Before any thread allocates: freed memory stays with the process (no trimming, no mmap for
// large blocks) and every thread allocates from one arena, so resident memory follows the peak
// in use, not when glibc hands pages back or which thread makes a new arena when. (Not under
// AddressSanitizer, whose allocator is not glibc's.)
const bool kMallocSet = !kResidentJudged || (mallopt(M_TRIM_THRESHOLD, 1 << 30) &&
                                             mallopt(M_MMAP_THRESHOLD, 32 << 20) &&
                                             mallopt(M_ARENA_MAX, 1));

uint32_t soak_frames() {
  const char* text = std::getenv("SIVIFLOW_SOAK_FRAMES");
  const long frames = text != nullptr ? std::strtol(text, nullptr, 10) : 0;
  return frames >= 500 ? static_cast<uint32_t>(frames) : kDefaultFrames;
}

// Resident set size of this process, bytes.
double resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE));
}

double mean(const std::vector<double>& v, size_t first, size_t end) {
  double sum = 0.0;
  for (size_t i = first; i < end; ++i) sum += v[i];
  return sum / static_cast<double>(end - first);
}

class SoakTest : public GpuTest {};

TEST_F(SoakTest, ResidentMemoryAndDeviceObjectsStayFlat) {
  ASSERT_TRUE(kMallocSet);
  const uint32_t frames = soak_frames();
  CreateInfo info = make_create_info(kSoakWidth, kSoakHeight);
  info.readback_images = 0;
  watch::install(info.get_device_proc_addr);
  info.get_device_proc_addr = &watch::get_device_proc_addr;
  ASSERT_TRUE(create_renderer(info).ok());
  HostTargets targets[2];
  for (HostTargets& slot : targets) {
    ASSERT_TRUE(create_sampled_targets({kSoakWidth, kSoakHeight}, &slot).ok());
  }

  std::vector<double> resident;
  resident.reserve(frames);
  watch::State after_warm_up;
  for (uint32_t frame = 0; frame < frames; ++frame) {
    const uint32_t slot = frame % 2;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    ASSERT_TRUE(context_->begin_slot(slot, &cmd).ok());
    ASSERT_TRUE(renderer_->begin_frame(slot).ok());
    const double time = frame / 30.0;
    const View view = camera_view(world_->scene_camera(time), {kSoakWidth, kSoakHeight});
    Status status = renderer_->update(view, time);
    ASSERT_TRUE(status.ok()) << "frame " << frame << ": " << status.message();
    status = record_world_and_water(cmd, slot, *world_, *renderer_, view, time, {}, &targets[slot]);
    ASSERT_TRUE(status.ok()) << "frame " << frame << ": " << status.message();
    ASSERT_TRUE(context_->end_slot_and_submit(slot).ok());
    resident.push_back(resident_bytes());
    if (frame + 1 == kWarmUpFrames) after_warm_up = watch::state;
  }
  for (uint32_t slot = 0; slot < 2; ++slot) ASSERT_TRUE(context_->wait_slot(slot).ok());

  // Windows of a thousand frames (a fifth of the run when shorter).
  const size_t window = std::min<size_t>(1000, (frames - kWarmUpFrames) / 5);
  const double first = mean(resident, kWarmUpFrames, kWarmUpFrames + window);
  const double last = mean(resident, frames - window, frames);
  // Views of the host's images are made per frame (the host may hand other images each frame)
  // and freed when the slot comes round: they may come, but not add up.
  const auto& created = watch::state.created;
  uint64_t made_after_warm_up = 0;
  for (int kind = 0; kind < watch::kKindCount; ++kind) {
    if (kind == watch::kImageView) continue;
    made_after_warm_up += created[kind] - after_warm_up.created[kind];
  }
  std::printf("%u frames: resident %.2f MiB over frames %u..%zu, %.2f MiB over the last %zu "
              "(%+.3f MiB); the renderer made %llu memory allocations, %llu buffers, %llu images, "
              "%llu descriptor pools, %llu set allocations, %llu of them after frame %u; image "
              "views alive %lld at frame %u, %lld at the end\n",
              frames, first / kMiB, kWarmUpFrames, kWarmUpFrames + window, last / kMiB, window,
              (last - first) / kMiB, static_cast<unsigned long long>(created[watch::kMemory]),
              static_cast<unsigned long long>(created[watch::kBuffer]),
              static_cast<unsigned long long>(created[watch::kImage]),
              static_cast<unsigned long long>(created[watch::kDescriptorPool]),
              static_cast<unsigned long long>(created[watch::kDescriptorSets]),
              static_cast<unsigned long long>(made_after_warm_up), kWarmUpFrames,
              static_cast<long long>(after_warm_up.alive[watch::kImageView]), kWarmUpFrames,
              static_cast<long long>(watch::state.alive[watch::kImageView]));
  if (kResidentJudged) {
    EXPECT_LE(last - first, 1.0 * kMiB) << "resident memory grows";
  } else {
    std::printf("resident memory not judged under AddressSanitizer (its quarantine keeps freed "
                "memory); LeakSanitizer judges the leaks at exit\n");
  }
  EXPECT_GT(created[watch::kMemory], 0u) << "the watched table is the renderer's";
  EXPECT_EQ(made_after_warm_up, 0u) << "memory, buffers, images, pools or sets after the warm-up";
  EXPECT_EQ(watch::state.alive, after_warm_up.alive) << "objects alive add up";
}

}  // namespace
}  // namespace siviflow::testing
