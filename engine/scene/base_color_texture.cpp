#include "scene/base_color_texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <csetjmp>
#include <cstdio>

#include <jerror.h>  // JWRN_JPEG_EOF
#include <jpeglib.h>
#include <png.h>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

Status extent_mismatch(const std::string& what, uint32_t width, uint32_t height,
                       const GltfImage& image) {
  return Status::error(text_format("%s: decodes to %ux%u but its header says %ux%u", what.c_str(),
                                   width, height, image.width, image.height));
}

Status decode_png(const GltfImage& image, const std::string& what, std::vector<uint8_t>* rgba) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&png, image.encoded.data(), image.encoded.size()) == 0) {
    return Status::error(what + ": PNG cannot be read: " + png.message);
  }
  if (png.width != image.width || png.height != image.height) {
    png_image_free(&png);
    return extent_mismatch(what, png.width, png.height, image);
  }
  png.format = PNG_FORMAT_RGBA;  // 8-bit sRGB: gray, palette and 16-bit files are converted
  // glTF base colour is sRGB at any depth; without this libpng takes an untagged 16-bit file as
  // linear and brightens it (mid-grey 32896 would become 186).
  png.flags |= PNG_IMAGE_FLAG_16BIT_sRGB;
  rgba->resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, rgba->data(), 0, nullptr) == 0) {
    return Status::error(what + ": PNG data is corrupt: " + png.message);
  }
  return Status::success();
}

// libjpeg reports fatal errors through error_exit, which must not return: it jumps back into
// decode_jpeg_rows. Only trivially destructible objects live in that function, so the jump
// skips no destructor.
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpeg_fail(j_common_ptr cinfo) {
  auto* error = reinterpret_cast<JpegError*>(cinfo->err);
  error->manager.format_message(cinfo, error->message);
  std::longjmp(error->jump, 1);
}

void jpeg_quiet(j_common_ptr) {}  // warnings (recoverable corruption) are not printed

// Warnings are decoded through, except running out of data: libjpeg would then invent the
// missing rows (grey) and report success.
void jpeg_warning(j_common_ptr cinfo, int msg_level) {
  if (msg_level < 0 && cinfo->err->msg_code == JWRN_JPEG_EOF) jpeg_fail(cinfo);
}

// Decodes into `rgba` (sized for the header's extent); on failure returns false and the reason
// is in error.message.
bool decode_jpeg_rows(const GltfImage& image, uint8_t* rgba, JpegError& error, uint32_t* width,
                      uint32_t* height) {
  jpeg_decompress_struct cinfo{};
  cinfo.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jpeg_fail;
  error.manager.output_message = jpeg_quiet;
  error.manager.emit_message = jpeg_warning;
  if (setjmp(error.jump) != 0) {
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, image.encoded.data(), static_cast<unsigned long>(image.encoded.size()));
  jpeg_read_header(&cinfo, TRUE);
  *width = cinfo.image_width;
  *height = cinfo.image_height;
  if (cinfo.image_width != image.width || cinfo.image_height != image.height) {
    jpeg_destroy_decompress(&cinfo);
    return true;  // the caller names the mismatch
  }
  cinfo.out_color_space = JCS_EXT_RGBA;  // libjpeg-turbo: gray and YCbCr expand to RGBA
  jpeg_start_decompress(&cinfo);
  const size_t stride = size_t{image.width} * 4;
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = rgba + cinfo.output_scanline * stride;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

Status decode_jpeg(const GltfImage& image, const std::string& what, std::vector<uint8_t>* rgba) {
  rgba->resize(size_t{image.width} * image.height * 4);
  JpegError error{};
  uint32_t width = 0;
  uint32_t height = 0;
  if (!decode_jpeg_rows(image, rgba->data(), error, &width, &height)) {
    return Status::error(what + ": JPEG cannot be decoded: " + error.message);
  }
  if (width != image.width || height != image.height) return extent_mismatch(what, width, height, image);
  return Status::success();
}

const std::array<float, 256>& srgb_to_linear_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const float c = static_cast<float>(i) / 255.0f;
      t[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }
    return t;
  }();
  return table;
}

uint8_t linear_to_srgb(float linear) {
  const float c = linear <= 0.0031308f ? linear * 12.92f : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::clamp(std::lround(c * 255.0f), 0L, 255L));
}

// Appends each level after mip 0 (already in texels): a 2x2 box in linear light for colour,
// plain for alpha; an odd size drops its last row or column (a side of 1 repeats its texel).
void build_mips(BaseColorTexture* texture) {
  const std::array<float, 256>& to_linear = srgb_to_linear_table();
  uint32_t width = texture->width;
  uint32_t height = texture->height;
  texture->mip_offsets = {0};
  while (width > 1 || height > 1) {
    const uint32_t next_width = std::max(1u, width / 2);
    const uint32_t next_height = std::max(1u, height / 2);
    const size_t source = texture->mip_offsets.back();
    texture->mip_offsets.push_back(texture->texels.size());
    texture->texels.resize(texture->texels.size() + size_t{next_width} * next_height * 4);
    const uint8_t* from = texture->texels.data() + source;
    uint8_t* to = texture->texels.data() + texture->mip_offsets.back();
    for (uint32_t y = 0; y < next_height; ++y) {
      for (uint32_t x = 0; x < next_width; ++x) {
        const uint32_t xs[2] = {std::min(2 * x, width - 1), std::min(2 * x + 1, width - 1)};
        const uint32_t ys[2] = {std::min(2 * y, height - 1), std::min(2 * y + 1, height - 1)};
        std::array<float, 4> sum{};
        for (uint32_t sy : ys) {
          for (uint32_t sx : xs) {
            const uint8_t* texel = from + (size_t{sy} * width + sx) * 4;
            for (int c = 0; c < 3; ++c) sum[c] += to_linear[texel[c]];
            sum[3] += texel[3];
          }
        }
        uint8_t* out = to + (size_t{y} * next_width + x) * 4;
        for (int c = 0; c < 3; ++c) out[c] = linear_to_srgb(sum[c] * 0.25f);
        out[3] = static_cast<uint8_t>(std::lround(sum[3] * 0.25f));
      }
    }
    width = next_width;
    height = next_height;
  }
}

}  // namespace

Status decode_base_color(const GltfImage& image, const std::string& what, BaseColorTexture* out) {
  if (image.width == 0 || image.height == 0 || image.width > kMaxGltfImageDimension ||
      image.height > kMaxGltfImageDimension) {
    return Status::error(text_format("%s: extent %ux%u is outside 1..%u", what.c_str(), image.width,
                                     image.height, kMaxGltfImageDimension));
  }
  BaseColorTexture texture;
  texture.width = image.width;
  texture.height = image.height;
  if (image.mime_type == "image/png") {
    SIVIFLOW_TRY(decode_png(image, what, &texture.texels));
  } else if (image.mime_type == "image/jpeg") {
    SIVIFLOW_TRY(decode_jpeg(image, what, &texture.texels));
  } else {
    return Status::error(what + ": not a PNG or JPEG image (" + image.mime_type + ")");
  }
  build_mips(&texture);
  *out = std::move(texture);
  return Status::success();
}

BaseColorTexture white_base_color() {
  BaseColorTexture texture;
  texture.width = 1;
  texture.height = 1;
  texture.texels = {255, 255, 255, 255};
  texture.mip_offsets = {0};
  return texture;
}

}  // namespace siviflow
