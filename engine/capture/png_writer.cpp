// PNG previews: linear float RGBA → clamped, sRGB-encoded 8-bit, encoded in memory with libpng
// and written atomically.
#include <png.h>

#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>

#include "siviflow/atomic_file.h"
#include "siviflow/image_files.h"

namespace siviflow {
namespace {

// libpng cannot hold rows wider than this in one png_size_t row buffer on every platform.
constexpr int kMaxPngDimension = 1 << 24;

// Shared with libpng callbacks: trivially destructible so longjmp may skip over it safely.
struct PngSink {
  std::vector<unsigned char>* bytes = nullptr;
  char error[256] = {};
  char warning[256] = {};  // libpng often explains an error in the warning just before it
};

// Stores libpng's message and longjmps back to encode_rows(); must not return.
void on_png_error(png_structp png, png_const_charp message) {
  auto* sink = static_cast<PngSink*>(png_get_error_ptr(png));
  if (sink != nullptr && sink->error[0] == '\0') {
    std::snprintf(sink->error, sizeof sink->error, "%s", message ? message : "libpng error");
  }
  png_longjmp(png, 1);
}

// Kept only to explain a following error; a warning alone does not fail the encode.
void on_png_warning(png_structp png, png_const_charp message) {
  auto* sink = static_cast<PngSink*>(png_get_error_ptr(png));
  if (sink != nullptr) {
    std::snprintf(sink->warning, sizeof sink->warning, "%s", message ? message : "");
  }
}

bool append(std::vector<unsigned char>* bytes, const unsigned char* data, size_t length) noexcept {
  try {
    bytes->insert(bytes->end(), data, data + length);
    return true;
  } catch (...) {
    return false;
  }
}

void on_png_write(png_structp png, png_bytep data, size_t length) {
  auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
  // The C++ exception stays in append(): only png_error's longjmp crosses libpng frames.
  if (!append(sink->bytes, data, length)) png_error(png, "out of memory");
}

void on_png_flush(png_structp) {}

struct PngHandles {
  png_structp png = nullptr;
  png_infop info = nullptr;
};

// Everything between setjmp and a possible longjmp lives in `handles` and `sink`, owned by the
// caller: no local here has a destructor to skip or a value to clobber.
bool encode_rows(PngHandles* handles, PngSink* sink, png_uint_32 width, png_uint_32 height,
                 int color_type, png_bytepp rows) {
  handles->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, on_png_error,
                                         on_png_warning);
  if (handles->png == nullptr) {
    std::snprintf(sink->error, sizeof sink->error, "cannot create the libpng writer");
    return false;
  }
  handles->info = png_create_info_struct(handles->png);
  if (handles->info == nullptr) {
    std::snprintf(sink->error, sizeof sink->error, "cannot create the libpng info");
    return false;
  }
  if (setjmp(png_jmpbuf(handles->png))) return false;
  png_set_write_fn(handles->png, sink, on_png_write, on_png_flush);
  png_set_IHDR(handles->png, handles->info, width, height, 8, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(handles->png, handles->info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(handles->png, handles->info);
  png_write_image(handles->png, rows);
  png_write_end(handles->png, nullptr);
  return true;
}

// Clamped to [0,1] (NaN → 0) and rounded; the beauty is linear so colour gets the sRGB curve.
unsigned char to_8bit(float value, bool srgb) {
  if (!(value > 0.0f)) return 0;
  if (value >= 1.0f) return 255;
  if (srgb) {
    value = value <= 0.0031308f ? 12.92f * value
                                : 1.055f * std::pow(value, 1.0f / 2.4f) - 0.055f;
  }
  return static_cast<unsigned char>(std::lround(value * 255.0f));
}

Status encode_png_named(int width, int height, const float* rgba, PngChannels channels,
                        const std::string& name, std::vector<unsigned char>* bytes) {
  const std::string what = "cannot encode PNG '" + name + "'";
  if (bytes == nullptr) return Status::error(what + ": no output buffer");
  if (width <= 0 || height <= 0 || width > kMaxPngDimension || height > kMaxPngDimension) {
    return Status::error(what + ": invalid size " + std::to_string(width) + "x" +
                         std::to_string(height));
  }
  if (rgba == nullptr) return Status::error(what + ": no RGBA pixels");

  const size_t components = channels == PngChannels::kRgba ? 4 : 3;
  const size_t w = static_cast<size_t>(width);
  const size_t h = static_cast<size_t>(height);
  std::vector<unsigned char> pixels(w * h * components);
  for (size_t i = 0; i < w * h; ++i) {
    for (size_t c = 0; c < components; ++c) {
      pixels[i * components + c] = to_8bit(rgba[i * 4 + c], c < 3);
    }
  }
  std::vector<png_bytep> rows(h);
  for (size_t y = 0; y < h; ++y) rows[y] = pixels.data() + y * w * components;

  bytes->clear();
  PngSink sink;
  sink.bytes = bytes;
  PngHandles handles;
  const bool ok = encode_rows(&handles, &sink, static_cast<png_uint_32>(width),
                              static_cast<png_uint_32>(height),
                              components == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB,
                              rows.data());
  png_destroy_write_struct(handles.png ? &handles.png : nullptr,
                           handles.info ? &handles.info : nullptr);
  if (!ok) {
    bytes->clear();
    std::string reason = sink.error;
    if (sink.warning[0] != '\0') reason += std::string(" (") + sink.warning + ")";
    return Status::error(what + ": " + reason);
  }
  return Status::success();
}

Status encode_png_guarded(int width, int height, const float* rgba, PngChannels channels,
                          const std::string& name, std::vector<unsigned char>* bytes) {
  try {
    return encode_png_named(width, height, rgba, channels, name, bytes);
  } catch (const std::exception& e) {
    if (bytes != nullptr) bytes->clear();
    try {
      return Status::error("cannot encode PNG '" + name + "': " + e.what());
    } catch (...) {
      return Status::error("out of memory");
    }
  }
}

}  // namespace

Status encode_png(int width, int height, const float* rgba, PngChannels channels,
                  std::vector<unsigned char>* bytes) {
  return encode_png_guarded(width, height, rgba, channels, "<memory>", bytes);
}

Status write_png(const std::string& path, int width, int height, const float* rgba,
                 PngChannels channels) {
  SIVIFLOW_TRY(check_output_path(path));  // fail before the costly encode
  std::vector<unsigned char> bytes;
  SIVIFLOW_TRY(encode_png_guarded(width, height, rgba, channels, path, &bytes));
  return write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace siviflow
