// A folder of captured frames (DIR/frame_NNNNN.exr, as `siviflow capture` writes them): which
// frames of a range are present, read whole, and agree with each other on what was captured.
// What `siviflow verify` reports, and what a resumed capture will trust.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "siviflow/status.h"

namespace siviflow {

// "frame_00042.exr".
std::string frame_file_name(uint32_t frame);

// What makes frames of one capture alike: what each of its frames must carry. The scene's path is
// not part of it (the frames record it for people): its content is.
struct FrameExpectation {
  std::string scene_digest;  // scene_content_digest; "" in frames of the layout before it
  float fps = 0.0f;
  int seed = 0;
  int width = 0;
  int height = 0;
  std::string aovs;                   // "depth,flow", as the capture names them
  // "NAME:TYPE" ("depth.Z:float"; types half, float, uint), sorted: frames whose channels are
  // named or typed otherwise are of another layout.
  std::vector<std::string> channels;
  std::string software_version;
};

enum class FrameState {
  kMissing,
  kIncomplete,  // OpenEXR cannot read it whole: a killed or failed write, or damage
  kMismatch,    // whole, but of another frame number or another capture
  kComplete,
};

struct FrameCheck {
  FrameState state = FrameState::kMissing;
  std::string problem;  // for all but kComplete: "missing", "cannot be read whole: ...", ...
};

// The frames of `dir` (its frame_NNNNN.exr files), in increasing order. Fails when the folder is
// missing, not a folder or cannot be listed.
Status list_frames(const std::string& dir, std::vector<uint32_t>* out);

// Checks frame `frame` of `dir` against `expected`; `expected_name` names it in the problem
// ("this capture", "frame_00000.exr").
FrameCheck check_frame(const std::string& dir, uint32_t frame, const FrameExpectation& expected,
                       const std::string& expected_name);

struct FrameProblem {
  uint32_t frame = 0;
  std::string file;     // the frame's file name in the folder
  std::string problem;  // "missing", "cannot be read whole: ...", "differs from ...: seed 3 (1)"
};

struct FrameFolderReport {
  uint32_t first = 0;  // the range checked: frames [first, end)
  uint32_t end = 0;
  uint32_t complete = 0;              // frames read whole and in agreement
  std::string reference;              // the frame the others were compared with ("" if none)
  std::vector<FrameProblem> problems;  // in frame order, one per bad frame
};

// Checks frames [first, end) of `dir`; with `end` 0, the range from the lowest to the highest
// frame file present. A frame is complete when OpenEXR reads every pixel of it, its frame number
// is its file's, and its FrameExpectation (scene content, fps, seed, size, AOVs, channels,
// software version) equals the first complete frame's. Fails (and leaves `out` alone) only when the folder itself cannot be
// checked: missing, not a folder, unreadable, or with no frame file and no range given.
Status check_frame_folder(const std::string& dir, uint32_t first, uint32_t end,
                          FrameFolderReport* out);

}  // namespace siviflow
