#include "siviflow/frame_folder.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <system_error>

#include "siviflow/image_files.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;

// The frame number of "frame_NNNNN.exr" (five digits or more, as %05u writes them).
std::optional<uint32_t> frame_of_file_name(const std::string& name) {
  constexpr std::string_view kPrefix = "frame_";
  constexpr std::string_view kSuffix = ".exr";
  if (name.size() < kPrefix.size() + 5 + kSuffix.size() || name.rfind(kPrefix, 0) != 0 ||
      name.compare(name.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0) {
    return std::nullopt;
  }
  const std::string digits =
      name.substr(kPrefix.size(), name.size() - kPrefix.size() - kSuffix.size());
  if (digits.size() > 10 || !std::all_of(digits.begin(), digits.end(), [](char c) {
        return c >= '0' && c <= '9';
      })) {
    return std::nullopt;
  }
  const unsigned long long frame = std::stoull(digits);
  if (frame > UINT32_MAX || frame_file_name(static_cast<uint32_t>(frame)) != name) {
    return std::nullopt;
  }
  return static_cast<uint32_t>(frame);
}

std::string joined(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ",") + name;
  return list;
}

const char* pixel_type_name(ExrPixelType type) {
  switch (type) {
    case ExrPixelType::kUint: return "uint";
    case ExrPixelType::kHalf: return "half";
    case ExrPixelType::kFloat: break;
  }
  return "float";
}

FrameExpectation expectation_of(const ExrImage& image) {
  FrameExpectation expected;
  expected.scene_digest = image.metadata.scene_digest;
  expected.fps = image.metadata.fps;
  expected.seed = image.metadata.seed;
  expected.width = image.width;
  expected.height = image.height;
  expected.aovs = image.metadata.aovs;
  for (const auto& [name, plane] : image.channels) {
    expected.channels.push_back(name + ":" + pixel_type_name(plane.type));
  }
  std::sort(expected.channels.begin(), expected.channels.end());
  expected.software_version = image.metadata.software_version;
  return expected;
}

// A digest short enough for a message line and long enough to tell two apart.
std::string short_digest(const std::string& digest) {
  constexpr size_t kShown = 7 + 12;  // "sha256:" and 12 hex digits
  if (digest.empty()) return "none";
  return digest.size() > kShown ? digest.substr(0, kShown) + "..." : digest;
}

// How `image` differs from `expected` ("" when it does not): every difference, what the capture
// is made of first.
std::string disagreement(const ExrImage& image, const FrameExpectation& expected,
                         const std::string& expected_name) {
  const FrameExpectation a = expectation_of(image);
  const FrameExpectation& b = expected;
  std::vector<std::string> differences;
  if (a.scene_digest.empty() != b.scene_digest.empty()) {
    // The frames before scene digests: another capture, whatever else they hold.
    const std::string attribute = kExrAttrSceneDigest;
    differences.push_back(a.scene_digest.empty()
                              ? "an earlier layout without " + attribute + " (one with it)"
                              : "a layout with " + attribute + " (an earlier one without it)");
  } else {
    if (a.scene_digest != b.scene_digest) {
      differences.push_back("scene content differs, digest " + short_digest(a.scene_digest) + " (" +
                            short_digest(b.scene_digest) + ")");
    }
    if (a.fps != b.fps) differences.push_back(text_format("fps %g (%g)", a.fps, b.fps));
    if (a.seed != b.seed) differences.push_back(text_format("seed %d (%d)", a.seed, b.seed));
    if (a.width != b.width || a.height != b.height) {
      differences.push_back(
          text_format("size %dx%d (%dx%d)", a.width, a.height, b.width, b.height));
    }
    if (a.aovs != b.aovs) {
      differences.push_back("AOVs " + (a.aovs.empty() ? std::string("none") : a.aovs) + " (" +
                            (b.aovs.empty() ? std::string("none") : b.aovs) + ")");
    } else if (a.channels != b.channels) {  // the AOVs' channels follow from the AOVs otherwise
      differences.push_back("channels " + joined(a.channels) + " (" + joined(b.channels) + ")");
    }
    if (a.software_version != b.software_version) {
      differences.push_back("software version '" + a.software_version + "' ('" +
                            b.software_version + "')");
    }
  }
  if (differences.empty()) return "";
  std::string text = "differs from " + expected_name + " (in brackets):";
  for (size_t i = 0; i < differences.size(); ++i) text += (i ? ", " : " ") + differences[i];
  return text;
}

// The reader's message without its "cannot read EXR '<path>': " lead, which the line already says.
std::string reader_problem(const std::string& message, const std::string& path) {
  const std::string lead = "cannot read EXR '" + path + "': ";
  return message.rfind(lead, 0) == 0 ? message.substr(lead.size()) : message;
}

// Reads frame `frame` whole into `image`; a state other than kComplete says why it could not.
FrameCheck read_frame(const std::string& dir, uint32_t frame, ExrImage* image) {
  const std::string path = (fs::path(dir) / frame_file_name(frame)).string();
  std::error_code error;
  if (!fs::exists(path, error)) return {FrameState::kMissing, "missing"};
  const Status read = read_exr(path, image);
  if (!read.ok()) {
    return {FrameState::kIncomplete,
            "cannot be read whole: " + reader_problem(read.message(), path)};
  }
  if (image->metadata.frame != static_cast<int>(frame)) {
    return {FrameState::kMismatch, text_format("holds frame %d", image->metadata.frame)};
  }
  return {FrameState::kComplete, ""};
}

Status frames_in(const std::string& dir, std::vector<uint32_t>* out) {
  std::error_code error;
  const fs::file_status status = fs::status(dir, error);
  if (!fs::exists(status)) return Status::error("'" + dir + "': no such folder");
  if (!fs::is_directory(status)) return Status::error("'" + dir + "': not a folder");
  std::vector<uint32_t> present;
  for (fs::directory_iterator it(dir, error), done; !error && it != done; it.increment(error)) {
    if (auto frame = frame_of_file_name(it->path().filename().string())) present.push_back(*frame);
  }
  if (error) return Status::error("'" + dir + "': cannot list the folder: " + error.message());
  std::sort(present.begin(), present.end());
  *out = std::move(present);
  return Status::success();
}

Status check_frames(const std::string& dir, uint32_t first, uint32_t end,
                    FrameFolderReport* out) {
  std::vector<uint32_t> present;  // only to find the range when none is given
  SIVIFLOW_TRY(frames_in(dir, &present));
  if (end == 0) {
    if (present.empty()) return Status::error("'" + dir + "': no frame_NNNNN.exr file in it");
    first = present.front();
    end = present.back() + 1;
  }

  FrameFolderReport report;
  report.first = first;
  report.end = end;
  std::optional<FrameExpectation> reference;
  for (uint32_t frame = first; frame < end; ++frame) {
    const std::string file = frame_file_name(frame);
    ExrImage image;
    FrameCheck check = read_frame(dir, frame, &image);
    if (check.state == FrameState::kComplete && reference) {
      check.problem = disagreement(image, *reference, report.reference);
    }
    if (!check.problem.empty()) {
      report.problems.push_back({frame, file, std::move(check.problem)});
      continue;
    }
    if (!reference) {
      reference = expectation_of(image);
      report.reference = file;
    }
    ++report.complete;
  }
  *out = std::move(report);
  return Status::success();
}

}  // namespace

FrameCheck check_frame(const std::string& dir, uint32_t frame, const FrameExpectation& expected,
                       const std::string& expected_name) {
  try {
    ExrImage image;
    FrameCheck check = read_frame(dir, frame, &image);
    if (check.state != FrameState::kComplete) return check;
    std::string differs = disagreement(image, expected, expected_name);
    if (differs.empty()) return check;
    return {FrameState::kMismatch, std::move(differs)};
  } catch (const std::exception& e) {
    return {FrameState::kIncomplete, std::string("cannot be checked: ") + e.what()};
  }
}

std::string frame_file_name(uint32_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05u.exr", frame);
  return name;
}

Status list_frames(const std::string& dir, std::vector<uint32_t>* out) {
  try {
    return frames_in(dir, out);
  } catch (const std::exception& e) {  // std::bad_alloc from a folder of millions of names
    return Status::error("'" + dir + "': " + e.what());
  }
}

Status check_frame_folder(const std::string& dir, uint32_t first, uint32_t end,
                          FrameFolderReport* out) {
  try {
    return check_frames(dir, first, end, out);
  } catch (const std::exception& e) {  // std::bad_alloc from a folder of millions of names
    return Status::error("'" + dir + "': " + e.what());
  }
}

}  // namespace siviflow
