// Capture files: EXR frames (HALF beauty + FLOAT data channels + metadata) and PNG previews,
// written atomically (temporary in the same folder, fsync, rename); EXR read-back for tests.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sim/status.h"

namespace siviflow {

// Header attribute names of the metadata every SiViFlow EXR carries.
inline constexpr const char* kExrAttrScene = "siviflow/scene";              // string
inline constexpr const char* kExrAttrFrame = "siviflow/frame";              // int
inline constexpr const char* kExrAttrTime = "siviflow/time";                // float, seconds
inline constexpr const char* kExrAttrSeed = "siviflow/seed";                // int
inline constexpr const char* kExrAttrSoftware = "siviflow/software_version";  // string

// One data channel: width * height floats, row-major, top-left origin; written as FLOAT.
// Names follow the single-part layer convention, e.g. "depth.Z", "flow.X", "water.mask".
struct ExrChannel {
  std::string name;
  const float* pixels = nullptr;
};

struct ExrMetadata {
  std::string scene;
  int frame = 0;
  float time_seconds = 0.0f;
  int seed = 0;
  std::string software_version;
};

// One frame to write. The caller keeps every pointed-to buffer alive during the call.
struct ExrFrame {
  int width = 0;
  int height = 0;
  const float* rgba = nullptr;  // linear beauty, 4 interleaved floats per pixel; written as HALF
  std::vector<ExrChannel> channels;
  ExrMetadata metadata;
};

// How many threads OpenEXR compresses a frame's line blocks on (0: the calling thread alone, the
// default). OpenEXR keeps one pool for the whole process, so this is process-wide: a host that
// writes frames while its cores would otherwise idle (the capture tool) sets it once.
Status set_exr_threads(int count);

// Encodes `frame` as a single-part scanline ZIP-compressed EXR into `bytes` (replaced).
Status encode_exr(const ExrFrame& frame, std::vector<char>* bytes);

// Encodes and writes atomically: on success `path` holds the complete file; on failure the
// previous content of `path` (if any) is untouched and no temporary file is left behind.
// Refuses an existing `path` that is not a regular file (directory, FIFO, device, symlink).
Status write_exr(const std::string& path, const ExrFrame& frame);

enum class PngChannels { kRgb, kRgba };

// PNG preview of linear float RGBA (4 interleaved floats per pixel, row-major, top-left
// origin): colour clamped to [0,1] then sRGB-encoded, alpha clamped and kept linear; 8 bit.
Status encode_png(int width, int height, const float* rgba, PngChannels channels,
                  std::vector<unsigned char>* bytes);
Status write_png(const std::string& path, int width, int height, const float* rgba,
                 PngChannels channels = PngChannels::kRgba);

// ---- Read-back (tests, golden comparisons). Goldens are trusted, in-repo files. ----

enum class ExrPixelType { kUint, kHalf, kFloat };

struct ExrPlane {
  ExrPixelType type = ExrPixelType::kFloat;  // as stored in the file
  std::vector<float> pixels;                 // width * height, row-major, top-left origin
};

struct ExrImage {
  int width = 0;
  int height = 0;
  std::map<std::string, ExrPlane> channels;  // every channel, e.g. "R", "A", "depth.Z"
  std::string compression;                   // "none", "zip", "piz", ...
  ExrMetadata metadata;  // from the siviflow/* attributes; defaults where one is absent
  std::map<std::string, std::string> string_attributes;
  std::map<std::string, int> int_attributes;
  std::map<std::string, float> float_attributes;

  // The plane's pixels, or nullptr when the image has no channel of that name.
  const std::vector<float>* find(const std::string& name) const;
};

// Reads every channel of a single-part scanline or tiled EXR as float planes.
Status read_exr(const std::string& path, ExrImage* image);

// Deep structural check of an EXR file (OpenEXR's checkOpenEXRFile): ok, or what is wrong.
Status check_exr_file(const std::string& path);

}  // namespace siviflow
