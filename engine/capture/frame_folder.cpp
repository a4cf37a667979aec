#include "siviflow/frame_folder.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <system_error>

#include "siviflow/image_files.h"
#include "sim/text_format.h"

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

std::string channel_list(const ExrImage& image) {
  std::string list;
  for (const auto& [name, plane] : image.channels) list += (list.empty() ? "" : ",") + name;
  return list;
}

// How `image` differs from the reference frame's ("" when it does not), every difference.
std::string disagreement(const ExrImage& image, const ExrImage& reference,
                         const std::string& reference_file) {
  std::vector<std::string> differences;
  const ExrMetadata& a = image.metadata;
  const ExrMetadata& b = reference.metadata;
  if (a.scene != b.scene) differences.push_back("scene '" + a.scene + "' ('" + b.scene + "')");
  if (a.seed != b.seed) differences.push_back(text_format("seed %d (%d)", a.seed, b.seed));
  if (image.width != reference.width || image.height != reference.height) {
    differences.push_back(text_format("size %dx%d (%dx%d)", image.width, image.height,
                                      reference.width, reference.height));
  }
  if (channel_list(image) != channel_list(reference)) {
    differences.push_back("channels " + channel_list(image) + " (" + channel_list(reference) +
                          ")");
  }
  if (a.software_version != b.software_version) {
    differences.push_back("software version '" + a.software_version + "' ('" +
                          b.software_version + "')");
  }
  if (differences.empty()) return "";
  std::string text = "differs from " + reference_file + " (in brackets):";
  for (size_t i = 0; i < differences.size(); ++i) text += (i ? ", " : " ") + differences[i];
  return text;
}

// The reader's message without its "cannot read EXR '<path>': " lead, which the line already says.
std::string reader_problem(const std::string& message, const std::string& path) {
  const std::string lead = "cannot read EXR '" + path + "': ";
  return message.rfind(lead, 0) == 0 ? message.substr(lead.size()) : message;
}

Status check_frames(const std::string& dir, uint32_t first, uint32_t end,
                    FrameFolderReport* out) {
  std::error_code error;
  const fs::file_status status = fs::status(dir, error);
  if (!fs::exists(status)) return Status::error("'" + dir + "': no such folder");
  if (!fs::is_directory(status)) return Status::error("'" + dir + "': not a folder");
  std::vector<uint32_t> present;
  for (fs::directory_iterator it(dir, error), done; !error && it != done; it.increment(error)) {
    if (auto frame = frame_of_file_name(it->path().filename().string())) present.push_back(*frame);
  }
  if (error) return Status::error("'" + dir + "': cannot list the folder: " + error.message());
  if (end == 0) {
    if (present.empty()) return Status::error("'" + dir + "': no frame_NNNNN.exr file in it");
    first = *std::min_element(present.begin(), present.end());
    end = *std::max_element(present.begin(), present.end()) + 1;
  }

  FrameFolderReport report;
  report.first = first;
  report.end = end;
  std::optional<ExrImage> reference;
  for (uint32_t frame = first; frame < end; ++frame) {
    const std::string file = frame_file_name(frame);
    const std::string path = (fs::path(dir) / file).string();
    const auto bad = [&](std::string problem) {
      report.problems.push_back({frame, file, std::move(problem)});
    };
    if (std::find(present.begin(), present.end(), frame) == present.end()) {
      bad("missing");
      continue;
    }
    ExrImage image;
    const Status read = read_exr(path, &image);
    if (!read.ok()) {
      bad("cannot be read whole: " + reader_problem(read.message(), path));
      continue;
    }
    if (image.metadata.frame != static_cast<int>(frame)) {
      bad(text_format("holds frame %d", image.metadata.frame));
      continue;
    }
    if (!reference) {
      reference = std::move(image);
      report.reference = file;
      ++report.complete;
      continue;
    }
    const std::string differs = disagreement(image, *reference, report.reference);
    if (differs.empty()) {
      ++report.complete;
    } else {
      bad(differs);
    }
  }
  *out = std::move(report);
  return Status::success();
}

}  // namespace

std::string frame_file_name(uint32_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05u.exr", frame);
  return name;
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
