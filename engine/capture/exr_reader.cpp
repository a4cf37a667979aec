// EXR read-back for tests, golden comparisons and frame checks: every channel of every part as a
// float plane.
#include <ImfChannelList.h>
#include <ImfCheckFile.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfIntAttribute.h>
#include <ImfMultiPartInputFile.h>
#include <ImfPartType.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <ImfTileDescriptionAttribute.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <set>

#include "exr_header_check.h"
#include "siviflow/atomic_file.h"
#include "siviflow/image_files.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// Caps on what a (possibly corrupt) header may make us allocate: 2^28 pixels, 4 GiB of floats.
constexpr int64_t kMaxReadPixels = int64_t{1} << 28;
constexpr int64_t kMaxReadSamples = int64_t{1} << 30;
// The most float-plane bytes one byte of a file can expand to. Deflate (zip, zips, pxr24) gives
// at most 1032:1, and a half widens to a float: 4096 bounds every codec but DWA with room to
// spare (a constant 8192x8192 image: zip 1786, piz 790, rle 120); DWA keeps one DC value per 8x8
// block before deflate, so it gets 64 times that (dwab 21752). Headers asking for more than
// this, past a free 64 MiB of planes, describe a file that cannot exist.
constexpr int64_t kMaxExpansion = 4096;
constexpr int64_t kMaxDwaExpansion = kMaxExpansion * 64;
constexpr int64_t kFreeReadBytes = int64_t{64} << 20;

const char* compression_name(Imf::Compression compression) {
  switch (compression) {
    case Imf::NO_COMPRESSION: return "none";
    case Imf::RLE_COMPRESSION: return "rle";
    case Imf::ZIPS_COMPRESSION: return "zips";
    case Imf::ZIP_COMPRESSION: return "zip";
    case Imf::PIZ_COMPRESSION: return "piz";
    case Imf::PXR24_COMPRESSION: return "pxr24";
    case Imf::B44_COMPRESSION: return "b44";
    case Imf::B44A_COMPRESSION: return "b44a";
    case Imf::DWAA_COMPRESSION: return "dwaa";
    case Imf::DWAB_COMPRESSION: return "dwab";
    default: return "unknown";
  }
}

ExrPixelType pixel_type(Imf::PixelType type) {
  switch (type) {
    case Imf::UINT: return ExrPixelType::kUint;
    case Imf::HALF: return ExrPixelType::kHalf;
    default: return ExrPixelType::kFloat;
  }
}

// Opening a FIFO or device would block or read endlessly: regular files only.
Status check_regular_file(const std::string& path, const std::string& what,
                          int64_t* bytes = nullptr) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return Status::error(what + ": " + errno_message(errno));
  if (!S_ISREG(st.st_mode)) return Status::error(what + ": not a regular file");
  if (bytes != nullptr) *bytes = st.st_size;
  return Status::success();
}

// a * b for sizes from an untrusted header (neither negative): INT64_MAX where it overflows.
int64_t saturating_product(int64_t a, int64_t b) {
  constexpr int64_t kMost = std::numeric_limits<int64_t>::max();
  return a != 0 && b > kMost / a ? kMost : a * b;
}

// Scan lines OpenEXR decodes together under a compression: its line buffers are this tall
// whatever the image's height.
int64_t lines_per_block(Imf::Compression compression) {
  switch (compression) {
    case Imf::NO_COMPRESSION:
    case Imf::RLE_COMPRESSION:
    case Imf::ZIPS_COMPRESSION: return 1;
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION: return 32;
    default: return 256;  // DWAB, and the most any codec takes
  }
}

// Found by fuzz_exr: OpenEXR sizes its read buffers from the header before reading any pixel. A
// tiled part's hold a row of tiles across the data window (a 534-byte file whose tiles were
// 4x16777220 made it allocate 4 GiB); a scan-line part's, a block of lines per thread (a 1-KiB
// DWAA file 4194312 pixels wide and 4 high, 1 GiB). Those buffers must fit what the file could
// hold, as the planes must: `buffer_bytes` adds up every part's so far, since a multi-part file
// keeps each part's until it closes.
Status check_read_buffers(const std::string& what, int64_t file_bytes, const Imf::Header& header,
                          int64_t width, int64_t channel_count, int64_t* buffer_bytes) {
  const int64_t sample_bytes = channel_count * int64_t{sizeof(float)};
  // The sum saturates: it only has to be too large.
  const auto add = [buffer_bytes](int64_t bytes) {
    *buffer_bytes = bytes > std::numeric_limits<int64_t>::max() - *buffer_bytes
                        ? std::numeric_limits<int64_t>::max()
                        : *buffer_bytes + bytes;
  };
  if (header.hasTileDescription()) {
    const Imf::TileDescription& tiles = header.tileDescription();
    add(saturating_product(
        saturating_product(std::max<int64_t>(tiles.xSize, width), tiles.ySize), sample_bytes));
    if ((*buffer_bytes - kFreeReadBytes) / kMaxDwaExpansion <= file_bytes) return Status::success();
    return Status::error(what + text_format(": its %ux%u tiles need buffers larger than a "
                                            "%lld-byte file can fill (corrupt or truncated)",
                                            tiles.xSize, tiles.ySize,
                                            static_cast<long long>(file_bytes)));
  }
  const int64_t line_buffers = std::max(1, 2 * Imf::globalThreadCount());
  const int64_t lines = lines_per_block(header.compression());
  add(saturating_product(saturating_product(width * lines, sample_bytes), line_buffers));
  if ((*buffer_bytes - kFreeReadBytes) / kMaxDwaExpansion <= file_bytes) return Status::success();
  return Status::error(what + text_format(": its %lld-pixel rows in blocks of %lld lines need "
                                          "buffers larger than a %lld-byte file can fill "
                                          "(corrupt or truncated)",
                                          static_cast<long long>(width),
                                          static_cast<long long>(lines),
                                          static_cast<long long>(file_bytes)));
}

// The fewest bytes of a file that could expand to `samples` float samples of this compression.
int64_t least_file_bytes(int64_t samples, Imf::Compression compression) {
  const bool dwa = compression == Imf::DWAA_COMPRESSION || compression == Imf::DWAB_COMPRESSION;
  return samples * int64_t{sizeof(float)} / (dwa ? kMaxDwaExpansion : kMaxExpansion);
}

// Refuses headers whose planes (`samples` so far, which take `least_bytes` of file at the least)
// could not come from a file of this size, before allocating them.
Status check_plausible_size(const std::string& what, int64_t file_bytes, int64_t samples,
                            int64_t least_bytes) {
  const int64_t plane_bytes = samples * int64_t{sizeof(float)};
  if (plane_bytes <= kFreeReadBytes || least_bytes <= file_bytes) return Status::success();
  return Status::error(what + text_format(": the header asks for %lld MiB of pixels, more than "
                                          "a %lld-byte file can hold (corrupt or truncated)",
                                          static_cast<long long>(plane_bytes >> 20),
                                          static_cast<long long>(file_bytes)));
}

// The string, int and float attributes of `header`, and the siviflow/* metadata among them.
void read_attributes(const Imf::Header& header, ExrImage* image) {
  for (auto it = header.begin(); it != header.end(); ++it) {
    const Imf::Attribute& attribute = it.attribute();
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&attribute)) {
      image->string_attributes[it.name()] = s->value();
    } else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&attribute)) {
      image->int_attributes[it.name()] = i->value();
    } else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&attribute)) {
      image->float_attributes[it.name()] = f->value();
    }
  }
  if (auto s = image->string_attributes.find(kExrAttrScene); s != image->string_attributes.end()) {
    image->metadata.scene = s->second;
  }
  if (auto s = image->string_attributes.find(kExrAttrSoftware);
      s != image->string_attributes.end()) {
    image->metadata.software_version = s->second;
  }
  if (auto i = image->int_attributes.find(kExrAttrFrame); i != image->int_attributes.end()) {
    image->metadata.frame = i->second;
  }
  if (auto i = image->int_attributes.find(kExrAttrSeed); i != image->int_attributes.end()) {
    image->metadata.seed = i->second;
  }
  if (auto f = image->float_attributes.find(kExrAttrTime); f != image->float_attributes.end()) {
    image->metadata.time_seconds = f->second;
  }
  if (Imf::hasFramesPerSecond(header)) {
    image->metadata.frames_per_second = double(Imf::framesPerSecond(header));
  }
  ExrCamera& camera = image->metadata.camera;
  camera.present = Imf::hasWorldToCamera(header);
  if (camera.present) {
    std::memcpy(camera.world_to_camera, &Imf::worldToCamera(header)[0][0],
                sizeof(camera.world_to_camera));
  }
  if (Imf::hasWorldToNDC(header)) {
    std::memcpy(camera.world_to_ndc, &Imf::worldToNDC(header)[0][0], sizeof(camera.world_to_ndc));
  }
  const auto float_attribute = [image](const char* name, float* out) {
    if (auto f = image->float_attributes.find(name); f != image->float_attributes.end()) {
      *out = f->second;
    }
  };
  float_attribute(kExrAttrFovY, &camera.fov_y_deg);
  float_attribute(kExrAttrNear, &camera.near_plane);
  float_attribute(kExrAttrFar, &camera.far_plane);
  if (auto s = image->string_attributes.find(kExrAttrSceneDigest);
      s != image->string_attributes.end()) {
    image->metadata.scene_digest = s->second;
  }
  if (auto f = image->float_attributes.find(kExrAttrFps); f != image->float_attributes.end()) {
    image->metadata.fps = f->second;
  }
  if (auto s = image->string_attributes.find(kExrAttrAovs); s != image->string_attributes.end()) {
    image->metadata.aovs = s->second;
  }
}

Status read_exr_impl(const std::string& path, ExrImage* out) {
  const std::string what = "cannot read EXR '" + path + "'";
  if (out == nullptr) return Status::error(what + ": no output image");
  int64_t file_bytes = 0;
  SIVIFLOW_TRY(check_regular_file(path, what, &file_bytes));
  SIVIFLOW_TRY(check_exr_headers(path, what, file_bytes));

  Imf::MultiPartInputFile file(path.c_str());
  const Imath::Box2i window = file.header(0).dataWindow();
  const int64_t width = int64_t{window.max.x} - window.min.x + 1;
  const int64_t height = int64_t{window.max.y} - window.min.y + 1;
  if (width <= 0 || height <= 0 || width * height > kMaxReadPixels) {
    return Status::error(what + ": unsupported data window " + std::to_string(width) + "x" +
                         std::to_string(height));
  }
  const int64_t pixel_count = width * height;

  ExrImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);

  // Every part's header is checked before any plane is allocated.
  int64_t samples = 0;
  int64_t least_bytes = 0;
  int64_t buffer_bytes = 0;
  std::set<std::string> names;
  for (int p = 0; p < file.parts(); ++p) {
    const Imf::Header& header = file.header(p);
    const std::string part = header.hasName() ? header.name() : "";
    const std::string where = file.parts() > 1 ? what + ": part '" + part + "'" : what;
    if (Imf::isDeepData(header.type())) {
      return Status::error(where + " holds deep data (unsupported)");
    }
    if (header.dataWindow() != window) {
      return Status::error(where + " has another data window than the first part (unsupported)");
    }
    image.parts.push_back(part);
    int64_t channel_count = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      ++channel_count;
      const Imf::Channel& channel = it.channel();
      if (channel.xSampling != 1 || channel.ySampling != 1) {
        return Status::error(where + ": channel '" + it.name() + "' is subsampled (unsupported)");
      }
      if (!names.insert(it.name()).second) {
        return Status::error(where + ": channel '" + it.name() +
                             "' is in an earlier part too (unsupported)");
      }
      samples += pixel_count * (channel.type == Imf::UINT ? 2 : 1);  // ids and their floats
      if (samples > kMaxReadSamples) return Status::error(where + ": too many samples");
    }
    least_bytes += least_file_bytes(channel_count * pixel_count, header.compression());
    SIVIFLOW_TRY(check_plausible_size(where, file_bytes, samples, least_bytes));
    SIVIFLOW_TRY(
        check_read_buffers(where, file_bytes, header, width, channel_count, &buffer_bytes));
  }

  for (int p = 0; p < file.parts(); ++p) {
    const Imf::Header& header = file.header(p);
    Imf::FrameBuffer frame_buffer;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      ExrPlane& plane = image.channels[it.name()];
      plane.type = pixel_type(it.channel().type);
      plane.compression = compression_name(header.compression());
      plane.pixels.assign(static_cast<size_t>(pixel_count), 0.0f);
      // Identifiers are read as stored, then rounded to floats, so that both stay exact.
      void* destination = plane.pixels.data();
      Imf::PixelType type = Imf::FLOAT;
      if (plane.type == ExrPixelType::kUint) {
        plane.ids.assign(static_cast<size_t>(pixel_count), 0u);
        destination = plane.ids.data();
        type = Imf::UINT;
      }
      frame_buffer.insert(it.name(), Imf::Slice::Make(type, destination, window, 4,
                                                      4 * static_cast<size_t>(width)));
    }
    {
      Imf::InputPart part(file, p);
      part.setFrameBuffer(frame_buffer);
      part.readPixels(window.min.y, window.max.y);
    }
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      ExrPlane& plane = image.channels[it.name()];
      for (size_t i = 0; i < plane.ids.size(); ++i) plane.pixels[i] = static_cast<float>(plane.ids[i]);
    }
    file.flushPartCache();  // this part's line or tile buffers go before the next part's come
  }
  read_attributes(file.header(0), &image);

  *out = std::move(image);
  return Status::success();
}

}  // namespace

const std::vector<float>* ExrImage::find(const std::string& name) const {
  auto it = channels.find(name);
  return it == channels.end() ? nullptr : &it->second.pixels;
}

Status read_exr(const std::string& path, ExrImage* image) {
  try {
    return read_exr_impl(path, image);
  } catch (const std::exception& e) {  // Iex::BaseExc derives from std::exception in 3.x
    try {
      return Status::error("cannot read EXR '" + path + "': " + e.what());
    } catch (...) {
      return Status::error("out of memory");
    }
  }
}

Status check_exr_file(const std::string& path) {
  try {
    const std::string what = "invalid EXR '" + path + "'";
    SIVIFLOW_TRY(check_regular_file(path, what));
    // Full (not reduced) checks, plus the OpenEXRCore pass: goldens are small.
    if (Imf::checkOpenEXRFile(path.c_str(), false, false, true)) {
      return Status::error(what + ": OpenEXR's file check found problems");
    }
    return Status::success();
  } catch (const std::exception& e) {
    try {
      return Status::error("cannot check EXR '" + path + "': " + e.what());
    } catch (...) {
      return Status::error("out of memory");
    }
  }
}

}  // namespace siviflow
