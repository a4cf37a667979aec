// Capture files: EXR frames (a HALF beauty; data channels as HALF, FLOAT or UINT; metadata) and
// PNG previews, written atomically (temporary in the same folder, fsync, rename); EXR read-back
// for tests.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "siviflow/status.h"

namespace siviflow {

// Header attribute names of the metadata every SiViFlow EXR carries (and the standard
// worldToCamera, worldToNDC and framesPerSecond).
inline constexpr const char* kExrAttrScene = "siviflow/scene";              // string
inline constexpr const char* kExrAttrFrame = "siviflow/frame";              // int
inline constexpr const char* kExrAttrTime = "siviflow/time";                // float, seconds
inline constexpr const char* kExrAttrSeed = "siviflow/seed";                // int
inline constexpr const char* kExrAttrSoftware = "siviflow/software_version";  // string
inline constexpr const char* kExrAttrFovY = "siviflow/fov_y";  // float, degrees, vertical
inline constexpr const char* kExrAttrNear = "siviflow/near";   // float, metres
inline constexpr const char* kExrAttrFar = "siviflow/far";     // float, metres
// What made the frame, beside the above: the scene's content ("sha256:<hex>",
// scene_content_digest), the frame rate of its time and the AOVs asked for ("depth,flow"; "" for
// the beauty alone). A frame without a digest is of the layout before them.
inline constexpr const char* kExrAttrSceneDigest = "siviflow/scene_digest";  // string
inline constexpr const char* kExrAttrFps = "siviflow/fps";                  // float, frames/s
inline constexpr const char* kExrAttrAovs = "siviflow/aovs";                // string

// One data channel: width * height samples, row-major, top-left origin; floats written as
// FLOAT, IEEE half bits written as HALF, or identifiers written as UINT (exactly one of the
// three). Names follow the layer convention, LAYER.C with a one-letter channel, e.g. "depth.Z",
// "flow.X", "water.A".
struct ExrChannel {
  std::string name;
  const float* pixels = nullptr;
  int stride = 1;  // samples from one pixel's to the next (4: a channel of interleaved RGBA)
  const uint32_t* ids = nullptr;
  const uint16_t* halves = nullptr;
};

// The lossless compressions a part may use (OpenEXR's RLE, ZIP at deflate level 1, PIZ).
enum class ExrCompression { kRle, kZip, kPiz };

// Channels written together as one part of a multi-part EXR, under the compression that suits
// their data.
struct ExrLayer {
  std::string name;  // the part's name, e.g. "depth"
  ExrCompression compression = ExrCompression::kZip;
  std::vector<ExrChannel> channels;
};

// The camera that made the frame, in OpenEXR's standard attributes' conventions (ImfStandard-
// Attributes.h): matrices multiply row vectors on their left (p' = p * M, Imath's order), which
// lays their 16 floats out as glm's column-major mat4 of the same transform. Camera space is
// x right, y up, z forward (left-handed); NDC is (0, 0) at the top-left corner of the image and
// (1, 1) at the bottom-right, after the homogeneous divide.
struct ExrCamera {
  bool present = false;  // read back: the file has worldToCamera
  float world_to_camera[16] = {};
  float world_to_ndc[16] = {};
  float fov_y_deg = 0.0f;  // vertical field of view
  float near_plane = 0.0f;  // metres
  float far_plane = 0.0f;
};

struct ExrMetadata {
  std::string scene;
  int frame = 0;
  float time_seconds = 0.0f;
  int seed = 0;
  std::string software_version;
  double frames_per_second = 0.0;  // written as the standard framesPerSecond (0: not written)
  ExrCamera camera;                // written when present
  std::string scene_digest;        // "" where the frame has none (the layout before it)
  float fps = 0.0f;                // as the capture's --fps (exactly: frames compare it)
  std::string aovs;
};

// One frame to write. The caller keeps every pointed-to buffer alive during the call. The
// beauty alone makes a single-part file; with layers, a multi-part file whose first part, "rgba",
// is the beauty (what a viewer shows first), then one part per layer, each with the metadata.
struct ExrFrame {
  int width = 0;
  int height = 0;
  // The linear beauty, 4 interleaved samples per pixel, written as HALF: either floats (rounded
  // to half) or IEEE half bits as rendered. Exactly one of the two.
  const float* rgba = nullptr;
  const uint16_t* rgba_half = nullptr;
  ExrCompression rgba_compression = ExrCompression::kZip;
  std::vector<ExrLayer> layers;
  ExrMetadata metadata;
};

// How many threads OpenEXR compresses a frame's line blocks on (0: the calling thread alone, the
// default). OpenEXR keeps one pool for the whole process, so this is process-wide: a host that
// writes frames while its cores would otherwise idle (the capture tool) sets it once.
Status set_exr_threads(int count);

// Encodes `frame` as a scanline EXR into `bytes` (replaced).
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
  std::string compression;                   // its part's: "none", "zip", "piz", ...
  std::vector<float> pixels;                 // width * height, row-major, top-left origin
  std::vector<uint32_t> ids;                 // kUint only: the exact values (pixels round them)
};

struct ExrImage {
  int width = 0;
  int height = 0;
  std::map<std::string, ExrPlane> channels;  // every channel of every part, e.g. "R", "depth.Z"
  std::vector<std::string> parts;            // the parts' names in file order ("" unnamed)
  // From the first part's header: the siviflow/* attributes (defaults where one is absent), and
  // every string, int and float attribute.
  ExrMetadata metadata;
  std::map<std::string, std::string> string_attributes;
  std::map<std::string, int> int_attributes;
  std::map<std::string, float> float_attributes;

  // The plane's pixels, or nullptr when the image has no channel of that name.
  const std::vector<float>* find(const std::string& name) const;
};

// Reads every channel of every part of a scanline or tiled EXR (single- or multi-part; the
// parts share one data window and no channel name) as float planes.
Status read_exr(const std::string& path, ExrImage* image);

// Deep structural check of an EXR file (OpenEXR's checkOpenEXRFile): ok, or what is wrong.
Status check_exr_file(const std::string& path);

}  // namespace siviflow
