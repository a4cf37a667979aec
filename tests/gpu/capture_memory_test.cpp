// A capture's frames after the first reuse the memory the first ones faulted in: memory freed and
// faulted in again every frame (the process's allocator handing blocks back to the kernel) costs
// a 720p capture a tenth of its time, and shows here as page faults that grow with the frames.
// And a long capture holds no more frames than its encoders and its own hands can (with every AOV
// a frame the writer holds is 34 bytes a pixel), and --force reads no frame it replaces.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "run_command.h"

namespace siviflow::testing {
namespace {

// Minor page faults of one capture of `frames` frames (through the shell, which waits for it).
long capture_page_faults(int frames, const std::string& out) {
  rusage before{};
  getrusage(RUSAGE_CHILDREN, &before);
  const RunResult r = run_siviflow("capture --frames " + std::to_string(frames) +
                                   " --size 320x180 --validation --force --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  rusage after{};
  getrusage(RUSAGE_CHILDREN, &after);
  return after.ru_minflt - before.ru_minflt;
}

TEST(CaptureMemory, LaterFramesFaultInNoFreshMemory) {
  const std::string out = fresh_test_dir("capture_memory").string();
  constexpr int kShortFrames = 3, kLongFrames = 11;
  const long short_run = capture_page_faults(kShortFrames, out);
  const long long_run = capture_page_faults(kLongFrames, out);
  // About 25 a frame; 3000 when OpenEXR's Huffman tables were mapped afresh for every block.
  const double per_frame = static_cast<double>(long_run - short_run) / (kLongFrames - kShortFrames);
  EXPECT_LT(per_frame, 500.0) << short_run << " faults for " << kShortFrames << " frames, "
                              << long_run << " for " << kLongFrames;
}

#ifdef __SANITIZE_ADDRESS__
// AddressSanitizer's quarantine holds freed memory back on purpose: resident memory says nothing
// there (as in soak_test.cpp); the captures still have to succeed.
constexpr bool kResidentJudged = false;
#else
constexpr bool kResidentJudged = true;
#endif

constexpr const char* kEveryAov = " --aov depth,flow,particles,normal,reflection,foam,motion";

// The peak resident size (KiB) of one run of `siviflow args`, made from a child process of its
// own: RUSAGE_CHILDREN keeps the largest descendant so far, so each run is measured alone.
long peak_kib_of(const std::string& args) {
  int ends[2];
  if (pipe(ends) != 0) return -1;
  const pid_t child = fork();
  if (child == 0) {
    close(ends[0]);
    const RunResult r = run_siviflow(args);
    if (r.exit_code != 0) std::fprintf(stderr, "siviflow %s:\n%s", args.c_str(), r.output.c_str());
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    const long peak = r.exit_code == 0 ? usage.ru_maxrss : -1;
    _exit(write(ends[1], &peak, sizeof peak) == sizeof peak ? 0 : 1);
  }
  close(ends[1]);
  long peak = -1;
  if (child < 0 || read(ends[0], &peak, sizeof peak) != sizeof peak) peak = -1;
  close(ends[0]);
  if (child > 0) waitpid(child, nullptr, 0);
  return peak;
}

TEST(CaptureMemory, ALongCaptureWithEveryAovHoldsNoQueueOfFrames) {
  const std::string options = " --size 960x540 --validation --force --out " +
                              fresh_test_dir("capture_memory_aovs").string() + kEveryAov;
  const long one_frame = peak_kib_of("capture --frames 1" + options);
  const long twelve_frames = peak_kib_of("capture --frames 12" + options);
  ASSERT_GT(one_frame, 0) << "the 1-frame capture failed";
  ASSERT_GT(twelve_frames, 0) << "the 12-frame capture failed";
  // Twelve frames add the second slot's readback buffers (1.5 frames), two frames in the
  // writer's hands and the second encoder's planes: 5.7 frames, measured. A queue of two frames
  // ahead of the encoders made it 7.7.
  const double frame_kib = 960.0 * 540.0 * 34.0 / 1024.0;
  if (kResidentJudged) {
    EXPECT_LT(static_cast<double>(twelve_frames - one_frame), 6.7 * frame_kib)
        << one_frame << " KiB for 1 frame, " << twelve_frames << " KiB for 12";
  }
}

TEST(CaptureMemory, AForcedCaptureReadsNoFrameItReplaces) {
  const std::string full = fresh_test_dir("capture_memory_full").string();
  const RunResult big = run_siviflow("capture --frames 1 --size 1920x1080 --validation --out " +
                                     full + kEveryAov);
  ASSERT_EQ(big.exit_code, 0) << big.output;
  const std::string small = "capture --frames 1 --size 320x180 --validation --force --out ";
  const long over_frame = peak_kib_of(small + full);
  const long in_empty_folder = peak_kib_of(small + fresh_test_dir("capture_memory_empty").string());
  ASSERT_GT(over_frame, 0) << "the capture over the 1920x1080 frame failed";
  ASSERT_GT(in_empty_folder, 0) << "the capture into an empty folder failed";
  // Reading the 1920x1080 frame with every AOV to check it took 55 MB more.
  if (kResidentJudged) {
    EXPECT_LT(over_frame - in_empty_folder, 20 * 1024)
        << over_frame << " KiB over the frame, " << in_empty_folder << " KiB without it";
  }
}

}  // namespace
}  // namespace siviflow::testing
