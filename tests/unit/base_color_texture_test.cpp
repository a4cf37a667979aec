// Base-colour texture decoding: PNG (every colour type and depth libpng expands) and JPEG into
// RGBA8 sRGB, the mip chain (layout and linear-light averages), and refusals that name the image
// and leave the output untouched. Every encoded image is made here, with libpng and libjpeg.
#include "scene/base_color_texture.h"

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "scene/gltf_import.h"
#include "siviflow/image_files.h"

namespace siviflow {
namespace {

// ---- Encoders ----

// RGBA8 / gray / colour-mapped bytes through libpng's simplified writer.
std::vector<uint8_t> simple_png(uint32_t width, uint32_t height, uint32_t format,
                                const void* pixels, const void* colormap = nullptr,
                                uint32_t colormap_entries = 0) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = width;
  image.height = height;
  image.format = format;
  image.colormap_entries = colormap_entries;
  png_alloc_size_t size = 0;
  EXPECT_NE(png_image_write_to_memory(&image, nullptr, &size, 0, pixels, 0, colormap), 0)
      << image.message;
  std::vector<uint8_t> bytes(size);
  EXPECT_NE(png_image_write_to_memory(&image, bytes.data(), &size, 0, pixels, 0, colormap), 0)
      << image.message;
  bytes.resize(size);
  return bytes;
}

// Colour spaces a low-level PNG may declare.
enum class PngTag { kNone, kSrgb, kLinearGamma };

void append_bytes(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + length);
}

// Any colour type and bit depth through libpng's low-level writer. `rows` holds the packed rows
// as PNG stores them (16-bit samples big-endian). Only trivially destructible state is touched
// after setjmp except `rows_at`, which is declared before it and outlives the jump.
bool raw_png(uint32_t width, uint32_t height, int bit_depth, int color_type,
             const std::vector<uint8_t>& rows, PngTag tag, std::vector<uint8_t>* out,
             const std::vector<png_color>& palette = {}, const std::vector<uint8_t>& trns = {}) {
  const size_t stride = rows.size() / height;
  std::vector<png_bytep> rows_at(height);
  for (uint32_t y = 0; y < height; ++y) {
    rows_at[y] = const_cast<png_bytep>(rows.data() + y * stride);
  }
  out->clear();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, out, append_bytes, nullptr);
  png_set_IHDR(png, info, width, height, bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (!palette.empty()) {
    png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  }
  if (!trns.empty()) {
    png_set_tRNS(png, info, trns.data(), static_cast<int>(trns.size()), nullptr);
  }
  if (tag == PngTag::kSrgb) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  if (tag == PngTag::kLinearGamma) png_set_gAMA_fixed(png, info, PNG_GAMMA_LINEAR);
  png_write_info(png, info);
  png_write_image(png, rows_at.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

struct JpegOptions {
  bool gray = false;
  bool full_chroma = true;  // no chroma subsampling, so that the tolerance can be tight
  bool progressive = false;
};

// `samples`: 3 (RGB) or 1 (gray) bytes per pixel. Quality 100.
std::vector<uint8_t> make_jpeg(uint32_t width, uint32_t height, const std::vector<uint8_t>& samples,
                               JpegOptions options = {}) {
  jpeg_compress_struct cinfo{};
  jpeg_error_mgr error{};
  cinfo.err = jpeg_std_error(&error);  // the encoder's input is ours and valid: default exit
  jpeg_create_compress(&cinfo);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = width;
  cinfo.image_height = height;
  cinfo.input_components = options.gray ? 1 : 3;
  cinfo.in_color_space = options.gray ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 100, TRUE);
  if (!options.gray && options.full_chroma) {
    for (int c = 0; c < 3; ++c) {
      cinfo.comp_info[c].h_samp_factor = 1;
      cinfo.comp_info[c].v_samp_factor = 1;
    }
  }
  if (options.progressive) jpeg_simple_progression(&cinfo);
  jpeg_start_compress(&cinfo, TRUE);
  const size_t stride = size_t{width} * static_cast<size_t>(cinfo.input_components);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(samples.data() + cinfo.next_scanline * stride);
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  std::vector<uint8_t> bytes(buffer, buffer + size);
  std::free(buffer);
  return bytes;
}

// As the importer keeps an image: the bytes, the sniffed MIME type and the header's extent.
GltfImage as_gltf_image(std::vector<uint8_t> encoded, const std::string& mime_type) {
  GltfImage image;
  image.encoded = std::move(encoded);
  image.mime_type = mime_type;
  const Status status = read_image_extent(image.encoded, "test image", &image.width, &image.height);
  EXPECT_TRUE(status.ok()) << status.message();
  return image;
}

GltfImage png_image(std::vector<uint8_t> encoded) {
  return as_gltf_image(std::move(encoded), "image/png");
}

GltfImage jpeg_image(std::vector<uint8_t> encoded) {
  return as_gltf_image(std::move(encoded), "image/jpeg");
}

// ---- Reference colour maths, in double, independent of the decoder's tables ----

double srgb_to_linear(double encoded) {
  const double c = encoded / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

int linear_to_srgb(double linear) {
  const double c =
      linear <= 0.0031308 ? linear * 12.92 : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::clamp(std::lround(c * 255.0), 0L, 255L));
}

// ---- Texture access ----

uint32_t level_extent(uint32_t size, size_t level) { return std::max(1u, size >> level); }

const uint8_t* texel(const BaseColorTexture& t, size_t level, uint32_t x, uint32_t y) {
  const uint32_t w = level_extent(t.width, level);
  return &t.texels[t.mip_offsets[level] + (size_t{y} * w + x) * 4];
}

std::vector<uint8_t> level_bytes(const BaseColorTexture& t, size_t level) {
  const size_t begin = t.mip_offsets[level];
  const size_t end = level + 1 < t.mip_offsets.size() ? t.mip_offsets[level + 1] : t.texels.size();
  return std::vector<uint8_t>(t.texels.begin() + static_cast<ptrdiff_t>(begin),
                              t.texels.begin() + static_cast<ptrdiff_t>(end));
}

// Checks the chain's layout: level l is max(1, size >> l), packed back to back, down to 1x1.
void expect_mip_layout(const BaseColorTexture& t, uint32_t width, uint32_t height) {
  ASSERT_EQ(t.width, width);
  ASSERT_EQ(t.height, height);
  size_t levels = 1;
  for (uint32_t m = std::max(width, height); m > 1; m >>= 1) ++levels;
  ASSERT_EQ(t.mip_offsets.size(), levels) << width << "x" << height;
  size_t offset = 0;
  for (size_t l = 0; l < levels; ++l) {
    EXPECT_EQ(t.mip_offsets[l], offset) << "level " << l << " of " << width << "x" << height;
    offset += size_t{level_extent(width, l)} * level_extent(height, l) * 4;
  }
  EXPECT_EQ(t.texels.size(), offset);
}

BaseColorTexture decode_ok(const GltfImage& image) {
  BaseColorTexture texture;
  const Status status = decode_base_color(image, "test image", &texture);
  EXPECT_TRUE(status.ok()) << status.message();
  return texture;
}

// The texture a failed decode must leave exactly as it was.
BaseColorTexture sentinel() {
  BaseColorTexture t;
  t.width = 7;
  t.height = 3;
  t.texels = {1, 2, 3, 4};
  t.mip_offsets = {0, 42};
  return t;
}

// Expects a refusal whose message starts with `what` and contains every one of `parts`, with
// `out` untouched and nothing printed to stderr (libpng and libjpeg would print by default).
void expect_refused(const GltfImage& image, const std::vector<std::string>& parts) {
  const std::string what = "duck.glb: image 3";
  BaseColorTexture out = sentinel();
  testing::internal::CaptureStderr();
  const Status status = decode_base_color(image, what, &out);
  const std::string printed = testing::internal::GetCapturedStderr();
  ASSERT_FALSE(status.ok()) << "accepted an image that should be refused";
  EXPECT_EQ(status.message().rfind(what + ": ", 0), 0u) << status.message();
  for (const std::string& part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << "'" << part << "' not in: " << status.message();
  }
  EXPECT_EQ(printed, "");
  const BaseColorTexture before = sentinel();
  EXPECT_EQ(out.width, before.width);
  EXPECT_EQ(out.height, before.height);
  EXPECT_EQ(out.texels, before.texels);
  EXPECT_EQ(out.mip_offsets, before.mip_offsets);
}

// Offset of the first IDAT chunk's data in a PNG, or 0.
size_t idat_data_offset(const std::vector<uint8_t>& png, uint32_t* length) {
  size_t at = 8;
  while (at + 8 <= png.size()) {
    const uint32_t n = (uint32_t{png[at]} << 24) | (uint32_t{png[at + 1]} << 16) |
                       (uint32_t{png[at + 2]} << 8) | png[at + 3];
    if (std::memcmp(png.data() + at + 4, "IDAT", 4) == 0) {
      *length = n;
      return at + 8;
    }
    at += 12 + size_t{n};
  }
  return 0;
}

// Deterministic bytes that compress poorly, so that the IDAT is long and damage lands in data.
std::vector<uint8_t> noise_bytes(size_t count, uint32_t seed) {
  std::vector<uint8_t> bytes(count);
  for (uint8_t& b : bytes) {
    seed = seed * 1664525u + 1013904223u;
    b = static_cast<uint8_t>(seed >> 24);
  }
  return bytes;
}

// A smooth RGB test card (gradients and a soft blob) that JPEG at quality 100 keeps closely.
std::vector<uint8_t> smooth_rgb(uint32_t width, uint32_t height) {
  std::vector<uint8_t> rgb(size_t{width} * height * 3);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      uint8_t* p = &rgb[(size_t{y} * width + x) * 3];
      const double dx = x - width * 0.4;
      const double dy = y - height * 0.6;
      p[0] = static_cast<uint8_t>(20 + 200 * x / std::max(1u, width - 1));
      p[1] = static_cast<uint8_t>(30 + 180 * y / std::max(1u, height - 1));
      p[2] =
          static_cast<uint8_t>(40 + 170 * std::exp(-(dx * dx + dy * dy) / (width * height * 0.2)));
    }
  }
  return rgb;
}

// ---- PNG ----

TEST(BaseColorPng, RgbaDecodesToTheExactBytesWithItsMipChain) {
  // 3x2 with distinct channels and alpha: any swizzle, flip or premultiplication shows.
  const std::vector<uint8_t> rgba = {255, 0,  0,  255, 0,  255, 0,  128, 0,  0,   255, 0,
                                     10,  20, 30, 40,  50, 60,  70, 80,  90, 100, 110, 120};
  const BaseColorTexture t = decode_ok(png_image(simple_png(3, 2, PNG_FORMAT_RGBA, rgba.data())));
  expect_mip_layout(t, 3, 2);
  ASSERT_EQ(t.mip_offsets.size(), 2u);
  EXPECT_EQ(level_bytes(t, 0), rgba);
  // 3x2 -> 1x1: the 2x2 box of columns 0-1 (column 2 has no partner at this level).
  const uint8_t* m = texel(t, 1, 0, 0);
  for (int c = 0; c < 3; ++c) {
    const double linear = (srgb_to_linear(rgba[c]) + srgb_to_linear(rgba[4 + c]) +
                           srgb_to_linear(rgba[12 + c]) + srgb_to_linear(rgba[16 + c])) /
                          4.0;
    EXPECT_NEAR(m[c], linear_to_srgb(linear), 1) << "channel " << c;
  }
  EXPECT_NEAR(m[3], (255 + 128 + 40 + 80) / 4.0, 0.5);
}

TEST(BaseColorPng, CheckerAveragesInLinearLightAndAlphaPlainly) {
  // Black transparent and white opaque: colour is the sRGB code of linear 0.5 (188, not 128);
  // alpha is coverage, averaged as is (128).
  const std::vector<uint8_t> rgba = {0,   0,   0,   0,   255, 255, 255, 255,
                                     255, 255, 255, 255, 0,   0,   0,   0};
  const BaseColorTexture t = decode_ok(png_image(simple_png(2, 2, PNG_FORMAT_RGBA, rgba.data())));
  expect_mip_layout(t, 2, 2);
  const uint8_t* m = texel(t, 1, 0, 0);
  EXPECT_EQ(linear_to_srgb(0.5), 188);
  EXPECT_EQ(m[0], 188);
  EXPECT_EQ(m[1], 188);
  EXPECT_EQ(m[2], 188);
  EXPECT_EQ(m[3], 128);
}

TEST(BaseColorPng, OddNonSquareChainMatchesAnIndependentBoxFilter) {
  // 5x3 -> 2x1 -> 1x1. Each level is checked against a reference built here in double from
  // the level above it, so an error anywhere in the chain shows at that level.
  const uint32_t width = 5;
  const uint32_t height = 3;
  const std::vector<uint8_t> rgba = noise_bytes(size_t{width} * height * 4, 7);
  const BaseColorTexture t =
      decode_ok(png_image(simple_png(width, height, PNG_FORMAT_RGBA, rgba.data())));
  expect_mip_layout(t, width, height);
  ASSERT_EQ(t.mip_offsets, (std::vector<size_t>{0, 60, 68}));
  ASSERT_EQ(t.texels.size(), 72u);
  EXPECT_EQ(level_bytes(t, 0), rgba);
  for (size_t level = 1; level < t.mip_offsets.size(); ++level) {
    const uint32_t sw = level_extent(width, level - 1);
    const uint32_t sh = level_extent(height, level - 1);
    for (uint32_t y = 0; y < level_extent(height, level); ++y) {
      for (uint32_t x = 0; x < level_extent(width, level); ++x) {
        std::array<double, 4> sum{};
        for (uint32_t dy = 0; dy < 2; ++dy) {
          for (uint32_t dx = 0; dx < 2; ++dx) {
            // A 1-texel dimension repeats its texel; otherwise 2x, 2x+1 exist.
            const uint8_t* s =
                texel(t, level - 1, std::min(2 * x + dx, sw - 1), std::min(2 * y + dy, sh - 1));
            for (int c = 0; c < 3; ++c) sum[c] += srgb_to_linear(s[c]);
            sum[3] += s[3];
          }
        }
        const uint8_t* m = texel(t, level, x, y);
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(m[c], linear_to_srgb(sum[c] / 4.0), 1)
              << "level " << level << " (" << x << "," << y << ") channel " << c;
        }
        EXPECT_NEAR(m[3], sum[3] / 4.0, 0.51) << "level " << level << " (" << x << "," << y << ")";
      }
    }
  }
  // By hand, level 1 texel (1,0) is the box of columns 2-3, rows 0-1 of mip 0.
  const uint8_t* m = texel(t, 1, 1, 0);
  double linear = 0.0;
  for (uint32_t y : {0u, 1u}) {
    for (uint32_t x : {2u, 3u}) linear += srgb_to_linear(rgba[(y * width + x) * 4]);
  }
  EXPECT_NEAR(m[0], linear_to_srgb(linear / 4.0), 1);
}

TEST(BaseColorPng, UniformBlocksKeepTheirCodeInEveryLevel) {
  // 64x16, each 2x2 block one code 0..255 (alpha the reverse): averaging equal texels in linear
  // light and converting back must give the same code, with no drift in the round trip.
  const uint32_t width = 64;
  const uint32_t height = 16;
  std::vector<uint8_t> rgba(size_t{width} * height * 4);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const uint8_t code = static_cast<uint8_t>((y / 2) * (width / 2) + x / 2);
      uint8_t* p = &rgba[(size_t{y} * width + x) * 4];
      p[0] = code;
      p[1] = static_cast<uint8_t>(code ^ 0x55);
      p[2] = static_cast<uint8_t>(code + 17);
      p[3] = static_cast<uint8_t>(255 - code);
    }
  }
  const BaseColorTexture t =
      decode_ok(png_image(simple_png(width, height, PNG_FORMAT_RGBA, rgba.data())));
  expect_mip_layout(t, width, height);
  for (uint32_t y = 0; y < height / 2; ++y) {
    for (uint32_t x = 0; x < width / 2; ++x) {
      const uint8_t* source = &rgba[(size_t{2 * y} * width + 2 * x) * 4];
      const uint8_t* m = texel(t, 1, x, y);
      ASSERT_EQ(std::vector<uint8_t>(m, m + 4), std::vector<uint8_t>(source, source + 4))
          << "block (" << x << "," << y << ")";
    }
  }
}

TEST(BaseColorPng, ChainLayoutForManyExtents) {
  const std::array<std::array<uint32_t, 2>, 7> extents = {
      {{1, 1}, {1, 4}, {4, 1}, {8, 2}, {7, 7}, {6, 33}, {130, 3}}};
  for (const auto& [width, height] : extents) {
    const std::vector<uint8_t> rgba = noise_bytes(size_t{width} * height * 4, width * 31 + height);
    const BaseColorTexture t =
        decode_ok(png_image(simple_png(width, height, PNG_FORMAT_RGBA, rgba.data())));
    expect_mip_layout(t, width, height);
    EXPECT_EQ(level_bytes(t, 0), rgba) << width << "x" << height;
  }
}

TEST(BaseColorPng, ColumnOfOneRepeatsItsTexelAcross) {
  // 1x2 -> 1x1: the lone column stands in for its missing partner, so the result is the
  // linear-light average of the two rows (not a blend with anything else).
  const std::vector<uint8_t> rgba = {0, 100, 255, 10, 255, 200, 0, 30};
  const BaseColorTexture t = decode_ok(png_image(simple_png(1, 2, PNG_FORMAT_RGBA, rgba.data())));
  expect_mip_layout(t, 1, 2);
  const uint8_t* m = texel(t, 1, 0, 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(m[c], linear_to_srgb((srgb_to_linear(rgba[c]) + srgb_to_linear(rgba[4 + c])) / 2),
                1);
  }
  EXPECT_EQ(m[3], 20);
}

TEST(BaseColorPng, SiviflowEncoderOutputDecodesToItsSrgbCodes) {
  // encode_png takes linear floats and sRGB-encodes colour; alpha stays linear.
  const std::vector<float> linear = {0.0f, 0.5f, 1.0f, 1.0f, 0.2f, 0.04f, 0.9f, 0.5f};
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(encode_png(2, 1, linear.data(), PngChannels::kRgba, &bytes).ok());
  const BaseColorTexture t = decode_ok(png_image({bytes.begin(), bytes.end()}));
  expect_mip_layout(t, 2, 1);
  for (int i = 0; i < 8; ++i) {
    const int expected =
        i % 4 == 3 ? static_cast<int>(std::lround(linear[i] * 255.0f)) : linear_to_srgb(linear[i]);
    EXPECT_NEAR(t.texels[i], expected, 1) << "sample " << i;
  }
}

TEST(BaseColorPng, GrayAndGrayAlphaExpandToRgba) {
  const std::vector<uint8_t> gray = {0, 64, 128, 255, 3, 77};
  const BaseColorTexture g = decode_ok(png_image(simple_png(3, 2, PNG_FORMAT_GRAY, gray.data())));
  expect_mip_layout(g, 3, 2);
  for (size_t i = 0; i < gray.size(); ++i) {
    const uint8_t* p = &g.texels[i * 4];
    EXPECT_EQ(std::vector<uint8_t>(p, p + 4),
              (std::vector<uint8_t>{gray[i], gray[i], gray[i], 255}))
        << "texel " << i;
  }
  const std::vector<uint8_t> ga = {10, 0, 200, 99, 255, 255, 40, 1};
  const BaseColorTexture a = decode_ok(png_image(simple_png(2, 2, PNG_FORMAT_GA, ga.data())));
  for (size_t i = 0; i < 4; ++i) {
    const uint8_t* p = &a.texels[i * 4];
    EXPECT_EQ(std::vector<uint8_t>(p, p + 4),
              (std::vector<uint8_t>{ga[2 * i], ga[2 * i], ga[2 * i], ga[2 * i + 1]}))
        << "texel " << i;
  }
}

TEST(BaseColorPng, LowBitDepthGrayExpandsToFullRange) {
  // 2-bit gray: codes 0..3 are 0, 85, 170, 255. Four pixels pack into one byte, MSB first.
  std::vector<uint8_t> out;
  ASSERT_TRUE(raw_png(4, 1, 2, PNG_COLOR_TYPE_GRAY, {0b00011011}, PngTag::kNone, &out));
  const BaseColorTexture t = decode_ok(png_image(out));
  expect_mip_layout(t, 4, 1);
  EXPECT_EQ(level_bytes(t, 0), (std::vector<uint8_t>{0, 0, 0, 255, 85, 85, 85, 255, 170, 170, 170,
                                                     255, 255, 255, 255, 255}));
}

TEST(BaseColorPng, PaletteWithTransparencyExpandsToRgba) {
  // Through the simplified writer (RGBA colour map: PLTE + tRNS)...
  const std::vector<uint8_t> colormap = {255, 0, 0, 255, 0, 128, 255, 64, 9, 8, 7, 0};
  const std::vector<uint8_t> indices = {0, 1, 2, 2, 1, 0};
  const BaseColorTexture t = decode_ok(
      png_image(simple_png(3, 2, PNG_FORMAT_RGBA_COLORMAP, indices.data(), colormap.data(), 3)));
  expect_mip_layout(t, 3, 2);
  for (size_t i = 0; i < indices.size(); ++i) {
    const uint8_t* p = &t.texels[i * 4];
    const uint8_t* c = &colormap[indices[i] * 4];
    EXPECT_EQ(std::vector<uint8_t>(p, p + 4), std::vector<uint8_t>(c, c + 4)) << "texel " << i;
  }
  // ...and a 4-bit palette file with a short tRNS (entries past it are opaque).
  std::vector<uint8_t> out;
  const std::vector<png_color> palette = {{1, 2, 3}, {40, 50, 60}, {200, 100, 0}};
  ASSERT_TRUE(
      raw_png(3, 1, 4, PNG_COLOR_TYPE_PALETTE, {0x01, 0x20}, PngTag::kNone, &out, palette, {17}));
  const BaseColorTexture p = decode_ok(png_image(out));
  EXPECT_EQ(level_bytes(p, 0),
            (std::vector<uint8_t>{1, 2, 3, 17, 40, 50, 60, 255, 200, 100, 0, 255}));
}

// 16-bit samples big-endian, as PNG stores them.
std::vector<uint8_t> be16_samples(const std::vector<uint16_t>& values) {
  std::vector<uint8_t> bytes;
  for (uint16_t v : values) {
    bytes.push_back(static_cast<uint8_t>(v >> 8));
    bytes.push_back(static_cast<uint8_t>(v & 0xFF));
  }
  return bytes;
}

TEST(BaseColorPng, SixteenBitSrgbConvertsToEightBit) {
  // A 16-bit file declared sRGB: each sample keeps its code, in 8 bits (v / 257).
  const std::vector<uint16_t> rgba = {0,     32896, 65535, 65535,   // 0, 128, 255 / opaque
                                      12850, 51400, 257,   32896};  // 50, 200, 1 / 128
  std::vector<uint8_t> out;
  ASSERT_TRUE(raw_png(2, 1, 16, PNG_COLOR_TYPE_RGB_ALPHA, be16_samples(rgba), PngTag::kSrgb, &out));
  const BaseColorTexture t = decode_ok(png_image(out));
  expect_mip_layout(t, 2, 1);
  for (size_t i = 0; i < rgba.size(); ++i) {
    EXPECT_NEAR(t.texels[i], rgba[i] / 257.0, 1.0) << "sample " << i;
  }
}

TEST(BaseColorPng, SixteenBitWithoutColourSpaceIsSrgbLikeEightBit) {
  // glTF base colour is sRGB whatever the depth; a 16-bit file that declares nothing must not
  // be taken as linear (libpng's simplified reader would, making mid-grey 32896 come out 188).
  const std::vector<uint16_t> gray = {0, 32896, 65535, 16448};
  std::vector<uint8_t> out;
  ASSERT_TRUE(raw_png(2, 2, 16, PNG_COLOR_TYPE_GRAY, be16_samples(gray), PngTag::kNone, &out));
  const BaseColorTexture t = decode_ok(png_image(out));
  for (size_t i = 0; i < gray.size(); ++i) {
    const uint8_t* p = &t.texels[i * 4];
    EXPECT_NEAR(p[0], gray[i] / 257.0, 1.0) << "texel " << i;
    EXPECT_EQ(p[0], p[1]);
    EXPECT_EQ(p[0], p[2]);
    EXPECT_EQ(p[3], 255);
  }
}

TEST(BaseColorPng, SixteenBitDeclaredLinearIsSrgbEncoded) {
  // gAMA 1.0: the samples are linear light, so 0.5 becomes about the sRGB code 188 (libpng
  // encodes with a 2.2 power law, which gives 186, so the tolerance is 3).
  const std::vector<uint16_t> rgb = {0, 32768, 65535};
  std::vector<uint8_t> out;
  ASSERT_TRUE(raw_png(1, 1, 16, PNG_COLOR_TYPE_RGB, be16_samples(rgb), PngTag::kLinearGamma, &out));
  const BaseColorTexture t = decode_ok(png_image(out));
  EXPECT_EQ(t.texels[0], 0);
  EXPECT_NEAR(t.texels[1], 188, 3);
  EXPECT_GT(t.texels[1], 160);  // far from 128, the code of a file taken as sRGB
  EXPECT_EQ(t.texels[2], 255);
  EXPECT_EQ(t.texels[3], 255);
}

// ---- JPEG ----

TEST(BaseColorJpeg, RgbDecodesCloseToTheSource) {
  // 13x7: partial MCUs on both edges. Quality 100 without chroma subsampling stays within a
  // few codes; the mip chain follows the usual layout.
  const uint32_t width = 13;
  const uint32_t height = 7;
  const std::vector<uint8_t> rgb = smooth_rgb(width, height);
  for (const bool progressive : {false, true}) {
    const BaseColorTexture t =
        decode_ok(jpeg_image(make_jpeg(width, height, rgb, {.progressive = progressive})));
    expect_mip_layout(t, width, height);
    int worst = 0;
    for (size_t i = 0; i < size_t{width} * height; ++i) {
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(t.texels[i * 4 + c] - rgb[i * 3 + c]));
      EXPECT_EQ(t.texels[i * 4 + 3], 255) << "texel " << i;
    }
    EXPECT_LE(worst, 4) << (progressive ? "progressive" : "baseline");
  }
}

TEST(BaseColorJpeg, SubsampledRgbStaysWithinTolerance) {
  const uint32_t width = 32;
  const uint32_t height = 16;
  const std::vector<uint8_t> rgb = smooth_rgb(width, height);
  const BaseColorTexture t =
      decode_ok(jpeg_image(make_jpeg(width, height, rgb, {.full_chroma = false})));
  int worst = 0;
  for (size_t i = 0; i < size_t{width} * height; ++i) {
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(t.texels[i * 4 + c] - rgb[i * 3 + c]));
  }
  EXPECT_LE(worst, 8);
}

TEST(BaseColorJpeg, GrayExpandsToRgba) {
  const uint32_t width = 9;
  const uint32_t height = 5;
  std::vector<uint8_t> gray(size_t{width} * height);
  for (size_t i = 0; i < gray.size(); ++i) gray[i] = static_cast<uint8_t>(10 + 5 * i);
  const BaseColorTexture t = decode_ok(jpeg_image(make_jpeg(width, height, gray, {.gray = true})));
  expect_mip_layout(t, width, height);
  for (size_t i = 0; i < gray.size(); ++i) {
    const uint8_t* p = &t.texels[i * 4];
    EXPECT_NEAR(p[0], gray[i], 2) << "texel " << i;
    EXPECT_EQ(p[1], p[0]);
    EXPECT_EQ(p[2], p[0]);
    EXPECT_EQ(p[3], 255);
  }
}

// ---- Refusals ----

TEST(BaseColorRefused, HeaderExtentThatDisagreesWithThePng) {
  const std::vector<uint8_t> rgba(3 * 2 * 4, 200);
  GltfImage image = png_image(simple_png(3, 2, PNG_FORMAT_RGBA, rgba.data()));
  image.width = 4;
  expect_refused(image, {"3x2", "4x2"});
  image.width = 3;
  image.height = 1;  // smaller than the real image: must not write past a 3x1 buffer
  expect_refused(image, {"3x2", "3x1"});
}

TEST(BaseColorRefused, HeaderExtentThatDisagreesWithTheJpeg) {
  GltfImage image = jpeg_image(make_jpeg(13, 7, smooth_rgb(13, 7)));
  image.width = 12;
  image.height = 7;
  expect_refused(image, {"13x7", "12x7"});
  image.width = 13;
  image.height = 70;
  expect_refused(image, {"13x7", "13x70"});
}

TEST(BaseColorRefused, TruncatedPng) {
  const std::vector<uint8_t> rgba = noise_bytes(16 * 16 * 4, 3);
  const std::vector<uint8_t> full = simple_png(16, 16, PNG_FORMAT_RGBA, rgba.data());
  for (const size_t keep : {full.size() / 2, full.size() - 13, size_t{33}}) {
    GltfImage image = png_image(full);
    image.encoded.resize(keep);
    SCOPED_TRACE("kept " + std::to_string(keep) + " of " + std::to_string(full.size()) + " bytes");
    expect_refused(image, {"PNG"});
  }
}

TEST(BaseColorRefused, PngWithDamagedImageData) {
  const std::vector<uint8_t> rgba = noise_bytes(16 * 16 * 4, 5);
  const GltfImage good = png_image(simple_png(16, 16, PNG_FORMAT_RGBA, rgba.data()));
  uint32_t length = 0;
  const size_t data = idat_data_offset(good.encoded, &length);
  ASSERT_GT(data, 0u);
  ASSERT_GT(length, 64u);
  GltfImage image = good;
  for (size_t i = 20; i < 28; ++i) image.encoded[data + i] ^= 0xFF;  // the CRC no longer matches
  expect_refused(image, {"PNG"});
  // The same damage with the chunk's CRC made to match: zlib's own check still catches it.
  const uint32_t crc = static_cast<uint32_t>(crc32(0, image.encoded.data() + data - 4, length + 4));
  for (int i = 0; i < 4; ++i) {
    image.encoded[data + length + i] = static_cast<uint8_t>(crc >> (24 - 8 * i));
  }
  expect_refused(image, {"PNG"});
  // Intact data with a wrong CRC: an IDAT CRC error is an error.
  GltfImage bad_crc = good;
  bad_crc.encoded[data + length] ^= 0x01;
  expect_refused(bad_crc, {"PNG"});
}

TEST(BaseColorRefused, TruncatedJpeg) {
  const std::vector<uint8_t> full = jpeg_image(make_jpeg(32, 32, smooth_rgb(32, 32))).encoded;
  // Cut inside the entropy-coded data (the header, with the extent, is intact) and in the
  // headers themselves.
  for (const size_t keep : {full.size() / 2, full.size() - 2, size_t{300}}) {
    GltfImage image = jpeg_image(full);
    image.encoded.resize(keep);
    SCOPED_TRACE("kept " + std::to_string(keep) + " of " + std::to_string(full.size()) + " bytes");
    expect_refused(image, {"JPEG"});
  }
}

TEST(BaseColorRefused, GarbageBytes) {
  GltfImage image;
  image.encoded = noise_bytes(200, 11);
  image.width = 4;
  image.height = 4;
  image.mime_type = "image/png";
  expect_refused(image, {"PNG"});
  image.mime_type = "image/jpeg";
  expect_refused(image, {"JPEG"});
  image.encoded.clear();
  expect_refused(image, {"JPEG"});
  image.mime_type = "image/png";
  expect_refused(image, {"PNG"});
}

TEST(BaseColorRefused, MimeTypeOtherThanPngOrJpeg) {
  const std::vector<uint8_t> rgba(4, 255);
  GltfImage image = png_image(simple_png(1, 1, PNG_FORMAT_RGBA, rgba.data()));
  image.mime_type = "image/webp";
  expect_refused(image, {"image/webp"});
  image.mime_type = "";
  expect_refused(image, {"not a PNG or JPEG"});
}

TEST(BaseColorRefused, ExtentOutsideTheCap) {
  const std::vector<uint8_t> rgba(4, 255);
  const GltfImage good = png_image(simple_png(1, 1, PNG_FORMAT_RGBA, rgba.data()));
  const std::string cap = std::to_string(kMaxGltfImageDimension);
  const std::array<std::array<uint32_t, 2>, 5> extents = {{{0, 1},
                                                           {1, 0},
                                                           {kMaxGltfImageDimension + 1, 1},
                                                           {1, kMaxGltfImageDimension + 1},
                                                           {0xFFFFFFFFu, 0xFFFFFFFFu}}};
  for (const auto& [width, height] : extents) {
    GltfImage image = good;
    image.width = width;
    image.height = height;
    SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
    expect_refused(image, {std::to_string(width) + "x" + std::to_string(height), cap});
  }
}

TEST(BaseColorRefused, AtTheCapIsAcceptedBeforeDecoding) {
  // kMaxGltfImageDimension itself passes the cap; the (1x1) file then disagrees with it.
  const std::vector<uint8_t> rgba(4, 255);
  GltfImage image = png_image(simple_png(1, 1, PNG_FORMAT_RGBA, rgba.data()));
  image.width = kMaxGltfImageDimension;
  expect_refused(image, {"decodes to 1x1", std::to_string(kMaxGltfImageDimension) + "x1"});
}

// ---- White ----

TEST(BaseColorWhite, OneOpaqueWhiteTexel) {
  const BaseColorTexture t = white_base_color();
  expect_mip_layout(t, 1, 1);
  EXPECT_EQ(t.texels, (std::vector<uint8_t>{255, 255, 255, 255}));
  EXPECT_EQ(t.mip_offsets, (std::vector<size_t>{0}));
}

}  // namespace
}  // namespace siviflow
