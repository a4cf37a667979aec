// Capture file writers: EXR/PNG round trips and the atomic-write guarantees.
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfFrameBuffer.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfStringAttribute.h>
#include <ImfTiledOutputPart.h>
#include <ImfPartType.h>
#include <ImfTiledOutputFile.h>
#include <ImfStandardAttributes.h>
#include <Imath/half.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <png.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <functional>
#include <string>
#include <vector>

#include "siviflow/image_files.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Deterministic, poorly compressible values in roughly [-2, 6).
struct Noise {
  uint32_t state = 12345u;
  float next() {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / static_cast<float>(1u << 24) * 8.0f - 2.0f;
  }
};

// Owns the pixel planes an ExrFrame points into.
struct TestFrame {
  int width = 0;
  int height = 0;
  std::vector<float> rgba;
  std::vector<float> depth;
  std::vector<float> flow_x;

  TestFrame(int w, int h) : width(w), height(h) {
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    Noise noise;
    rgba.resize(n * 4);
    depth.resize(n);
    flow_x.resize(n);
    for (float& v : rgba) v = noise.next();
    for (float& v : depth) v = noise.next() * 1000.0f + 0.123456789f;
    for (float& v : flow_x) v = noise.next() * 1e-3f;
  }

  ExrFrame frame() const {
    ExrFrame f;
    f.width = width;
    f.height = height;
    f.rgba = rgba.data();
    f.layers = {{"depth", ExrCompression::kZip, {{"depth.Z", depth.data()}}},
                {"flow", ExrCompression::kRle, {{"flow.X", flow_x.data()}}}};
    f.metadata.scene = "straight_river";
    f.metadata.frame = 42;
    f.metadata.time_seconds = 1.75f;
    f.metadata.seed = -7;
    f.metadata.software_version = "siviflow 0.1.0-test";
    f.metadata.scene_digest = "sha256:00112233445566778899aabbccddeeff";
    f.metadata.fps = 23.976f;
    f.metadata.aovs = "depth,flow";
    return f;
  }
};

class ImageFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "siviflow_image_files_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr) << std::strerror(errno);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // read_exr must refuse `file` with a message naming it and holding `problem`; the message.
  std::string expect_refused(const std::string& file, const std::string& problem) const {
    ExrImage image;
    const Status read = read_exr(file, &image);
    EXPECT_FALSE(read.ok()) << file;
    EXPECT_NE(read.message().find(problem), std::string::npos) << read.message();
    EXPECT_NE(read.message().find(file), std::string::npos) << read.message();
    return read.message();
  }
  // The same for `bytes`, written to `name` in the test's folder.
  std::string expect_refused(const std::string& name, const std::string& bytes,
                             const std::string& problem) const {
    write_text(path(name), bytes);
    return expect_refused(path(name), problem);
  }

  std::string dir_;
};

using ImageFilesExr = ImageFilesTest;
using ImageFilesAtomic = ImageFilesTest;
using ImageFilesPng = ImageFilesTest;

TEST_F(ImageFilesExr, RoundTripKeepsPixelsChannelsAndMetadata) {
  TestFrame data(7, 5);
  // Edge values: a half rounding tie (1000.25), a half subnormal (1e-6), FLOAT max.
  data.rgba[0] = 0.5f;
  data.rgba[1] = 1e-6f;
  data.rgba[2] = 1000.25f;
  data.rgba[3] = 1.0f;
  data.depth[0] = std::numeric_limits<float>::max();
  data.depth[1] = 1e-30f;
  const std::string file = path("frame.exr");
  const Status written = write_exr(file, data.frame());
  ASSERT_TRUE(written.ok()) << written.message();
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"frame.exr"});  // no temporary left

  ExrImage image;
  const Status read = read_exr(file, &image);
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(image.width, 7);
  EXPECT_EQ(image.height, 5);
  ASSERT_EQ(image.channels.size(), 6u);
  const char* rgba_names[4] = {"R", "G", "B", "A"};
  for (size_t c = 0; c < 4; ++c) {
    ASSERT_NE(image.find(rgba_names[c]), nullptr) << rgba_names[c];
    EXPECT_EQ(image.channels.at(rgba_names[c]).type, ExrPixelType::kHalf);
    const std::vector<float>& plane = *image.find(rgba_names[c]);
    for (size_t i = 0; i < plane.size(); ++i) {
      const float original = data.rgba[i * 4 + c];
      // Exactly the round-to-nearest half, hence within half's relative precision 2^-11.
      EXPECT_EQ(plane[i], static_cast<float>(half(original))) << rgba_names[c] << " " << i;
      EXPECT_NEAR(plane[i], original, std::abs(original) * 4.9e-4f + 6e-8f);
    }
  }
  EXPECT_EQ((*image.find("R"))[0], 0.5f);
  EXPECT_EQ((*image.find("B"))[0], 1000.0f);  // half spacing at 1000 is 0.5: ties to even
  EXPECT_EQ((*image.find("A"))[0], 1.0f);

  ASSERT_NE(image.find("depth.Z"), nullptr);
  ASSERT_NE(image.find("flow.X"), nullptr);
  EXPECT_EQ(image.channels.at("depth.Z").type, ExrPixelType::kFloat);
  EXPECT_EQ(image.channels.at("flow.X").type, ExrPixelType::kFloat);
  EXPECT_EQ(*image.find("depth.Z"), data.depth);  // FLOAT is bit-exact
  EXPECT_EQ(*image.find("flow.X"), data.flow_x);
  EXPECT_EQ((*image.find("depth.Z"))[0], std::numeric_limits<float>::max());

  EXPECT_EQ(image.metadata.scene, "straight_river");
  EXPECT_EQ(image.metadata.frame, 42);
  EXPECT_EQ(image.metadata.time_seconds, 1.75f);
  EXPECT_EQ(image.metadata.seed, -7);
  EXPECT_EQ(image.metadata.software_version, "siviflow 0.1.0-test");
  EXPECT_EQ(image.string_attributes.at(kExrAttrScene), "straight_river");
  EXPECT_EQ(image.int_attributes.at(kExrAttrFrame), 42);
  EXPECT_EQ(image.float_attributes.at(kExrAttrTime), 1.75f);
  // What made the frame.
  EXPECT_EQ(image.metadata.scene_digest, "sha256:00112233445566778899aabbccddeeff");
  EXPECT_EQ(image.metadata.fps, 23.976f);
  EXPECT_EQ(image.metadata.aovs, "depth,flow");
  EXPECT_EQ(image.string_attributes.at("siviflow/scene_digest"),
            "sha256:00112233445566778899aabbccddeeff");
  EXPECT_EQ(image.float_attributes.at("siviflow/fps"), 23.976f);
  EXPECT_EQ(image.string_attributes.at("siviflow/aovs"), "depth,flow");

  const Status checked = check_exr_file(file);
  EXPECT_TRUE(checked.ok()) << checked.message();
}

TEST_F(ImageFilesExr, PartsHaveTheirLayersCompressionAndTopLeftWindow) {
  TestFrame data(16, 9);
  ExrFrame frame = data.frame();
  frame.rgba_compression = ExrCompression::kPiz;
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, frame).ok());

  Imf::MultiPartInputFile input(file.c_str());
  ASSERT_EQ(input.parts(), 3);
  const char* names[3] = {"rgba", "depth", "flow"};
  const Imf::Compression compressions[3] = {Imf::PIZ_COMPRESSION, Imf::ZIP_COMPRESSION,
                                            Imf::RLE_COMPRESSION};
  for (int p = 0; p < 3; ++p) {
    const Imf::Header& header = input.header(p);
    EXPECT_EQ(header.name(), names[p]);
    EXPECT_EQ(header.type(), Imf::SCANLINEIMAGE);
    EXPECT_EQ(header.compression(), compressions[p]) << names[p];
    EXPECT_EQ(header.lineOrder(), Imf::INCREASING_Y);
    EXPECT_EQ(header.dataWindow().min, Imath::V2i(0, 0));
    EXPECT_EQ(header.dataWindow().max, Imath::V2i(15, 8));
    EXPECT_EQ(header.displayWindow(), header.dataWindow());
    EXPECT_FALSE(Imf::hasChromaticities(header));  // sRGB primaries are the spec default
    // Every part carries the metadata, for tools that read one part.
    EXPECT_EQ(header.typedAttribute<Imf::IntAttribute>(kExrAttrFrame).value(), 42) << names[p];
    EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>(kExrAttrSceneDigest).value(),
              "sha256:00112233445566778899aabbccddeeff")
        << names[p];
  }
  EXPECT_EQ(input.header(0).channels().findChannel("G")->type, Imf::HALF);
  EXPECT_EQ(input.header(1).channels().findChannel("depth.Z")->type, Imf::FLOAT);
  EXPECT_EQ(input.header(0).channels().findChannel("depth.Z"), nullptr);

  ExrImage image;
  ASSERT_TRUE(read_exr(file, &image).ok());
  EXPECT_EQ(image.parts, (std::vector<std::string>{"rgba", "depth", "flow"}));
  EXPECT_EQ(image.channels.at("G").compression, "piz");
  EXPECT_EQ(image.channels.at("depth.Z").compression, "zip");
  EXPECT_EQ(image.channels.at("flow.X").compression, "rle");
  // Row-major, top-left origin: pixel (x=3, y=2) of the input is pixel (3, 2) of the file.
  const size_t index = 2 * 16 + 3;
  EXPECT_EQ((*image.find("depth.Z"))[index], data.depth[index]);
  EXPECT_EQ((*image.find("flow.X"))[index], data.flow_x[index]);
}

TEST_F(ImageFilesExr, BeautyAloneIsASinglePartFile) {
  TestFrame data(8, 4);
  ExrFrame frame = data.frame();
  frame.layers.clear();
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, frame).ok());
  const std::string bytes = read_text(file);
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(static_cast<unsigned char>(bytes[5]) & 0x10, 0);  // no multi-part bit in the version
  Imf::InputFile input(file.c_str());  // the single-part interface reads it
  EXPECT_EQ(input.header().compression(), Imf::ZIP_COMPRESSION);
  EXPECT_NE(input.header().channels().findChannel("A"), nullptr);
}

TEST_F(ImageFilesExr, HalfBeautyIsWrittenBitForBitAndStridedChannelsAreGathered) {
  TestFrame data(6, 3);
  const size_t pixels = 6 * 3;
  std::vector<uint16_t> halves(pixels * 4);
  for (size_t i = 0; i < halves.size(); ++i) halves[i] = half(data.rgba[i]).bits();
  halves[0] = half(std::numeric_limits<float>::infinity()).bits();
  std::vector<float> normal(pixels * 4);  // RGBA interleaved, as the GPU reads it back
  for (size_t i = 0; i < normal.size(); ++i) normal[i] = static_cast<float>(i) * 0.25f;
  ExrFrame frame = data.frame();
  frame.rgba = nullptr;
  frame.rgba_half = halves.data();
  frame.layers = {{"normal", ExrCompression::kRle,
                   {{"normal.X", normal.data(), 4}, {"normal.Z", normal.data() + 2, 4}}},
                  {"motion", ExrCompression::kZip,
                   {{.name = "motion.X", .stride = 4, .halves = halves.data()},
                    {.name = "motion.W", .stride = 4, .halves = halves.data() + 3}}}};
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, frame).ok());

  ExrImage image;
  ASSERT_TRUE(read_exr(file, &image).ok());
  const char* rgba_names[4] = {"R", "G", "B", "A"};
  for (size_t c = 0; c < 4; ++c) {
    for (size_t i = 0; i < pixels; ++i) {
      EXPECT_EQ(half(image.channels.at(rgba_names[c]).pixels[i]).bits(), halves[i * 4 + c]);
    }
  }
  EXPECT_TRUE(std::isinf(image.channels.at("R").pixels[0]));
  for (size_t i = 0; i < pixels; ++i) {
    EXPECT_EQ(image.channels.at("normal.X").pixels[i], normal[i * 4]);
    EXPECT_EQ(image.channels.at("normal.Z").pixels[i], normal[i * 4 + 2]);
  }
  // Data channels given as halves are HALF, gathered from their stride bit for bit.
  EXPECT_EQ(image.channels.at("motion.X").type, ExrPixelType::kHalf);
  EXPECT_EQ(image.channels.at("normal.X").type, ExrPixelType::kFloat);
  for (size_t i = 0; i < pixels; ++i) {
    EXPECT_EQ(half(image.channels.at("motion.X").pixels[i]).bits(), halves[i * 4]);
    EXPECT_EQ(half(image.channels.at("motion.W").pixels[i]).bits(), halves[i * 4 + 3]);
  }
}

// Identifiers go in as UINT and come back exact (beyond a float's 2^24), beside their floats;
// the camera and frame rate come back as written, in OpenEXR's standard attributes.
TEST_F(ImageFilesExr, IdentifiersAsUintAndTheCameraInStandardAttributes) {
  TestFrame data(5, 2);
  std::vector<uint32_t> ids(10);
  for (uint32_t i = 0; i < ids.size(); ++i) ids[i] = i == 3 ? 0u : (1u << 24) + 1u + i;
  ExrFrame frame = data.frame();
  frame.layers.push_back({"particle", ExrCompression::kZip, {{"particle.I", nullptr, 1, ids.data()}}});
  frame.metadata.frames_per_second = 24000.0 / 1001.0;
  ExrCamera& camera = frame.metadata.camera;
  camera.present = true;
  for (int i = 0; i < 16; ++i) {
    camera.world_to_camera[i] = static_cast<float>(i) * 0.5f - 1.0f;
    camera.world_to_ndc[i] = static_cast<float>(i * i) * 0.01f;
  }
  camera.fov_y_deg = 47.5f;
  camera.near_plane = 0.25f;
  camera.far_plane = 750.0f;
  const std::string file = path("ids.exr");
  ASSERT_TRUE(write_exr(file, frame).ok());
  {  // as another reader sees it: the standard attributes and types
    Imf::MultiPartInputFile input(file.c_str());
    const Imf::Header& header = input.header(0);
    ASSERT_TRUE(Imf::hasWorldToCamera(header));
    ASSERT_TRUE(Imf::hasWorldToNDC(header));
    EXPECT_EQ(Imf::worldToCamera(header)[0][1], camera.world_to_camera[1]);  // row 0, column 1
    EXPECT_EQ(Imf::worldToNDC(header)[3][2], camera.world_to_ndc[14]);
    EXPECT_EQ(Imf::framesPerSecond(header).n, 24000);
    EXPECT_EQ(Imf::framesPerSecond(header).d, 1001u);
    EXPECT_EQ(input.header(3).channels().findChannel("particle.I")->type, Imf::UINT);
  }
  ExrImage image;
  ASSERT_TRUE(read_exr(file, &image).ok());
  const ExrPlane& plane = image.channels.at("particle.I");
  EXPECT_EQ(plane.type, ExrPixelType::kUint);
  EXPECT_EQ(plane.ids, ids);
  EXPECT_EQ(plane.pixels[3], 0.0f);
  EXPECT_EQ(plane.pixels[0], static_cast<float>(ids[0]));
  EXPECT_TRUE(image.channels.at("depth.Z").ids.empty());
  EXPECT_NEAR(image.metadata.frames_per_second, 23.976, 1e-3);
  const ExrCamera& back = image.metadata.camera;
  ASSERT_TRUE(back.present);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(back.world_to_camera[i], camera.world_to_camera[i]) << i;
    EXPECT_EQ(back.world_to_ndc[i], camera.world_to_ndc[i]) << i;
  }
  EXPECT_EQ(back.fov_y_deg, 47.5f);
  EXPECT_EQ(back.near_plane, 0.25f);
  EXPECT_EQ(back.far_plane, 750.0f);

  ExrFrame both = data.frame();
  both.layers.push_back({"particle", ExrCompression::kZip,
                         {{"particle.I", data.depth.data(), 1, ids.data()}}});
  const Status s = write_exr(path("both.exr"), both);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'particle.I' needs its pixels as floats, halves or ids, one of the"),
            std::string::npos)
      << s.message();
}

TEST_F(ImageFilesExr, FileBytesEqualInMemoryEncoding) {
  TestFrame data(10, 4);
  std::vector<char> encoded;
  ASSERT_TRUE(encode_exr(data.frame(), &encoded).ok());
  ASSERT_GT(encoded.size(), 0u);
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, data.frame()).ok());
  const std::string on_disk = read_text(file);
  EXPECT_EQ(on_disk, std::string(encoded.begin(), encoded.end()));
}

TEST_F(ImageFilesExr, InvalidFramesAreRejectedWithoutFiles) {
  TestFrame data(4, 4);
  const std::string file = path("frame.exr");

  ExrFrame zero_size = data.frame();
  zero_size.width = 0;
  Status s = write_exr(file, zero_size);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("invalid size 0x4"), std::string::npos) << s.message();

  ExrFrame no_pixels = data.frame();
  no_pixels.rgba = nullptr;
  EXPECT_FALSE(write_exr(file, no_pixels).ok());

  ExrFrame both_beauties = data.frame();
  const std::vector<uint16_t> halves(4 * 4 * 4);
  both_beauties.rgba_half = halves.data();
  s = write_exr(file, both_beauties);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("one of the two"), std::string::npos) << s.message();

  ExrFrame duplicate = data.frame();
  duplicate.layers[1].channels.push_back({"depth.Z", data.depth.data()});
  s = write_exr(file, duplicate);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'depth.Z' is used twice"), std::string::npos) << s.message();

  ExrFrame clashes_with_beauty = data.frame();
  clashes_with_beauty.layers[0].channels.push_back({"A", data.depth.data()});
  EXPECT_FALSE(write_exr(file, clashes_with_beauty).ok());

  for (const auto& [layer_name, problem] :
       {std::pair{"rgba", "is the beauty's part"}, {"flow", "is empty or used twice"},
        {"", "is empty or used twice"}}) {
    ExrFrame bad_layer = data.frame();
    bad_layer.layers.push_back({layer_name, ExrCompression::kZip, {{"foam.Y", data.depth.data()}}});
    s = write_exr(file, bad_layer);
    EXPECT_FALSE(s.ok()) << layer_name;
    EXPECT_NE(s.message().find("layer name '" + std::string(layer_name) + "' " + problem),
              std::string::npos)
        << s.message();
  }

  ExrFrame no_stride = data.frame();
  no_stride.layers[0].channels[0].stride = 0;
  s = write_exr(file, no_stride);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'depth.Z' has stride 0 (at least 1)"), std::string::npos)
      << s.message();

  ExrFrame empty_layer = data.frame();
  empty_layer.layers.push_back({"foam", ExrCompression::kZip, {}});
  s = write_exr(file, empty_layer);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("layer 'foam' has no channels"), std::string::npos) << s.message();

  ExrFrame null_channel = data.frame();
  null_channel.layers[0].channels.push_back({"water.A", nullptr});
  s = write_exr(file, null_channel);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(file), std::string::npos) << s.message();

  ExrFrame floats_and_halves = data.frame();
  floats_and_halves.layers[0].channels.push_back(
      {.name = "water.A", .pixels = data.depth.data(), .halves = halves.data()});
  s = write_exr(file, floats_and_halves);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'water.A' needs its pixels as floats, halves or ids"),
            std::string::npos)
      << s.message();

  EXPECT_FALSE(encode_exr(data.frame(), nullptr).ok());
  EXPECT_TRUE(list_dir(dir_).empty());
}

TEST_F(ImageFilesExr, ReadAndCheckReportTruncatedFiles) {
  TestFrame data(32, 32);
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, data.frame()).ok());
  const std::string bytes = read_text(file);
  const std::string truncated = path("truncated.exr");
  write_text(truncated, bytes.substr(0, bytes.size() / 2));

  ExrImage image;
  const Status read = read_exr(truncated, &image);
  EXPECT_FALSE(read.ok());
  EXPECT_NE(read.message().find(truncated), std::string::npos) << read.message();
  const Status checked = check_exr_file(truncated);
  EXPECT_FALSE(checked.ok());
  EXPECT_NE(checked.message().find(truncated), std::string::npos) << checked.message();

  const Status missing = read_exr(path("absent.exr"), &image);
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("No such file"), std::string::npos) << missing.message();
}

// Overwrites the 4-byte little-endian int `index` places after the header attribute `name`'s
// size field (0: the size itself) in `bytes`.
// (Every part's header has the attribute: `which` picks the first, the last or every one.)
enum class Which { kFirst, kLast, kEvery };
void patch_attribute_int(std::string* bytes, const std::string& name, const std::string& type,
                         int index, int32_t value, Which which = Which::kFirst) {
  const std::string key = name + std::string(1, '\0') + type + std::string(1, '\0');
  size_t at = which == Which::kLast ? bytes->rfind(key) : bytes->find(key);
  ASSERT_NE(at, std::string::npos) << name;
  for (; at != std::string::npos; at = bytes->find(key, at + key.size())) {
    std::memcpy(bytes->data() + at + key.size() + 4 * index, &value, 4);
    if (which != Which::kEvery) break;
  }
}

// Found by fuzz_exr: OpenEXR sizes an attribute from its size field before reading it, so a
// short file claiming a 2 GiB attribute made it allocate and clear 2 GiB (seconds per file).
TEST_F(ImageFilesExr, ReadRefusesAttributeLargerThanTheFile) {
  TestFrame data(16, 16);
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, data.frame()).ok());  // three parts, each with the metadata
  for (const Which which : {Which::kFirst, Which::kLast}) {
    std::string bytes = read_text(file);
    patch_attribute_int(&bytes, kExrAttrScene, "string", 0, 0x7ffffff0, which);
    expect_refused("huge_attribute.exr", bytes,
                   "attribute 'siviflow/scene' claims 2147483632 bytes");
  }

  // A fixed-size type is read whole whatever its size field says, as OpenEXR reads it.
  std::string compression = read_text(file);
  patch_attribute_int(&compression, "compression", "compression", 0, 0x7ffffff0);
  const std::string fixed_file = path("fixed.exr");
  write_text(fixed_file, compression);
  ExrImage image;
  const Status fixed = read_exr(fixed_file, &image);
  EXPECT_TRUE(fixed.ok()) << fixed.message();
}

// Found by fuzz_exr: OpenEXR reads a channel list up to its empty name, not by its size field, so
// a walk that skipped by the size found this file's headers ending early, while OpenEXR went on
// to an attribute of an unknown type claiming 1.8 GB, and allocated it.
TEST_F(ImageFilesExr, ReadWalksChannelListsAsOpenExrReadsThem) {
  const unsigned char file[] = {
      0x76, 0x2f, 0x31, 0x01, 0x02, 0x10, 0x00, 0x00, 0x63, 0x68, 0x61, 0x6e, 0x6e, 0x65, 0x6c,
      0x73, 0x00, 0x63, 0x68, 0x6c, 0x69, 0x73, 0x74, 0x00, 0x49, 0x00, 0x00, 0x00, 0x41, 0x00,
      0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x47, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x52, 0x00, 0x01, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x6f, 0x6e, 0x00, 0x01, 0x00, 0x00, 0x00, 0x04,
      0x64, 0x61, 0x74, 0x61, 0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77, 0x00, 0x62, 0x6f, 0x78, 0x32,
      0x69, 0x00, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f,
      0x00, 0x00, 0x00, 0x11, 0x70, 0x6c, 0x61, 0x79, 0x57, 0x69, 0x6e, 0x64, 0x6f, 0x77, 0x00,
      0x62, 0xff, 0xff, 0xff, 0xff, 0xff, 0x2f, 0x31, 0xff, 0x01};
  expect_refused("channel_list.exr", std::string(reinterpret_cast<const char*>(file), sizeof(file)),
                 "claims");
}

// Found by fuzz_exr: a 460-byte file whose data window said 8454152x4 made the reader allocate
// its 400 MiB of planes before OpenEXR found the pixels missing.
TEST_F(ImageFilesExr, ReadRefusesDataWindowTheFileCannotHold) {
  TestFrame data(16, 16);
  ExrFrame beauty = data.frame();
  beauty.layers.clear();
  const std::string file = path("frame.exr");
  ASSERT_TRUE(write_exr(file, beauty).ok());
  std::string bytes = read_text(file);
  patch_attribute_int(&bytes, "dataWindow", "box2i", 3, 8000000);  // xMax
  const std::string message = expect_refused(
      "huge_window.exr", bytes, "more than a " + std::to_string(bytes.size()) + "-byte");
  EXPECT_NE(message.find("(corrupt or truncated)"), std::string::npos) << message;
}

// Found by the hour-long fuzz_exr run: a tiled file whose tiles were 4x16777220 made OpenEXR
// allocate 4 GiB of tile buffers before reading a pixel.
TEST_F(ImageFilesExr, ReadRefusesTilesTheFileCannotFill) {
  const std::string file = path("tiled.exr");
  {
    Imf::Header header(8, 4);
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    header.setTileDescription(Imf::TileDescription(4, 4, Imf::ONE_LEVEL));
    std::vector<float> pixels(32, 0.5f);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()),
                                        sizeof(float), sizeof(float) * 8));
    Imf::TiledOutputFile out(file.c_str(), header);
    out.setFrameBuffer(frame_buffer);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
  }
  ExrImage image;
  ASSERT_TRUE(read_exr(file, &image).ok()) << "the file as written reads";
  std::string bytes = read_text(file);
  patch_attribute_int(&bytes, "tiles", "tiledesc", 2, 16777220);  // ySize
  expect_refused("huge_tiles.exr", bytes, "its 4x16777220 tiles need buffers larger than a");

  // Found by fuzz_exr under UBSan: the buffers' size of such tiles overflowed.
  patch_attribute_int(&bytes, "tiles", "tiledesc", 1, 0x7fffffff);  // xSize
  patch_attribute_int(&bytes, "tiles", "tiledesc", 2, 0x7fffffff);  // ySize
  expect_refused("huge_tiles.exr", bytes, "its 2147483647x2147483647 tiles need buffers");
}

// Found by fuzz_exr: a preview's size is its width times its height times 4, which overflowed.
TEST_F(ImageFilesExr, ReadRefusesPreviewLargerThanTheFile) {
  std::string bytes("v/1\x01\x02\0\0\0preview\0preview\0\x08\0\0\0", 28);
  bytes += std::string(8, '\xff');  // 4294967295 x 4294967295
  bytes += std::string(1, '\0');
  expect_refused("preview.exr", bytes, "attribute 'preview' claims");
}

// Found by fuzz_exr: OpenEXR decodes DWAA in blocks of 32 lines, whatever the image's height, so
// a short image of enormous width made it allocate 1 GiB of line buffers from a 1-KiB file.
TEST_F(ImageFilesExr, ReadRefusesLineBuffersTheFileCannotFill) {
  const std::string file = path("short.exr");
  {
    Imf::Header header(8, 4);
    header.compression() = Imf::DWAA_COMPRESSION;
    header.channels().insert("Y", Imf::Channel(Imf::HALF));
    std::vector<half> pixels(32, half(0.5f));
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("Y", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(pixels.data()),
                                        sizeof(half), sizeof(half) * 8));
    Imf::OutputFile out(file.c_str(), header);
    out.setFrameBuffer(frame_buffer);
    out.writePixels(4);
  }
  ExrImage image;
  ASSERT_TRUE(read_exr(file, &image).ok()) << "the file as written reads";
  std::string bytes = read_text(file);
  patch_attribute_int(&bytes, "dataWindow", "box2i", 3, 4194311);  // xMax: the block stays one
  expect_refused("wide.exr", bytes, "its 4194312-pixel rows in blocks of 32 lines need buffers");
}

// Each part of a multi-part file keeps its tile buffers until the file closes: 40 parts whose
// 1x33554432 tiles each pass alone (128 MiB of buffers) need 5 GiB together from 11 KiB.
TEST_F(ImageFilesExr, ReadRefusesTilesThePartsTogetherCannotFill) {
  constexpr int kParts = 40;
  const std::string file = path("tiled_parts.exr");
  {
    std::vector<Imf::Header> headers(kParts, Imf::Header(1, 1));
    for (int p = 0; p < kParts; ++p) {
      headers[p].setName("part" + std::to_string(p));
      headers[p].setType(Imf::TILEDIMAGE);
      headers[p].channels().insert("C" + std::to_string(p), Imf::Channel(Imf::FLOAT));
      headers[p].setTileDescription(Imf::TileDescription(1, 1, Imf::ONE_LEVEL));
    }
    Imf::MultiPartOutputFile out(file.c_str(), headers.data(), kParts);
    float pixel = 0.5f;
    for (int p = 0; p < kParts; ++p) {
      Imf::FrameBuffer frame_buffer;
      frame_buffer.insert("C" + std::to_string(p),
                          Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(&pixel), 4, 4));
      Imf::TiledOutputPart part(out, p);
      part.setFrameBuffer(frame_buffer);
      part.writeTile(0, 0);
    }
  }
  ExrImage image;
  ASSERT_TRUE(read_exr(file, &image).ok()) << "the file as written reads";
  EXPECT_EQ(image.channels.size(), size_t{kParts});
  std::string bytes = read_text(file);
  patch_attribute_int(&bytes, "tiles", "tiledesc", 2, 1 << 25, Which::kEvery);  // ySize
  const std::string message =
      expect_refused("huge_tiled_parts.exr", bytes, "tiles need buffers larger than a");
  EXPECT_EQ(message.find("part 'part0'"), std::string::npos) << "part 0 alone passes";
}

// A two-part file from another tool: part "a" holds channel `first` over 8x4 pixels, part "b"
// holds `second` over `b_window`.
void write_two_parts(const std::string& file, const char* first, const char* second,
                     const Imath::Box2i& b_window) {
  std::vector<Imf::Header> headers(2, Imf::Header(8, 4));
  headers[1].dataWindow() = b_window;
  const char* channels[2] = {first, second};
  for (int p = 0; p < 2; ++p) {
    headers[p].setName(p == 0 ? "a" : "b");
    headers[p].setType(Imf::SCANLINEIMAGE);
    headers[p].channels().insert(channels[p], Imf::Channel(Imf::FLOAT));
  }
  Imf::MultiPartOutputFile out(file.c_str(), headers.data(), 2);
  std::vector<float> pixels(64, 0.5f);
  for (int p = 0; p < 2; ++p) {
    const Imath::Box2i window = headers[p].dataWindow();
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert(channels[p], Imf::Slice::Make(Imf::FLOAT, pixels.data(), window,
                                                      sizeof(float), sizeof(float) * 8));
    Imf::OutputPart part(out, p);
    part.setFrameBuffer(frame_buffer);
    part.writePixels(window.max.y - window.min.y + 1);
  }
}

TEST_F(ImageFilesExr, ReadRefusesPartsItCannotMerge) {
  const Imath::Box2i same(Imath::V2i(0, 0), Imath::V2i(7, 3));
  const std::string twice = path("twice.exr");
  write_two_parts(twice, "Z", "Z", same);
  expect_refused(twice, "part 'b': channel 'Z' is in an earlier part too");

  const std::string windows = path("windows.exr");
  write_two_parts(windows, "Y", "Z", Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(3, 3)));
  expect_refused(windows, "part 'b' has another data window");

  const std::string good = path("good.exr");
  write_two_parts(good, "Y", "Z", same);
  ExrImage image;
  const Status read = read_exr(good, &image);
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(image.parts, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(image.channels.size(), 2u);
}

TEST_F(ImageFilesExr, ReadRefusesFifoWithoutBlocking) {
  const std::string fifo = path("pipe.exr");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  ExrImage image;
  const Status read = read_exr(fifo, &image);
  EXPECT_FALSE(read.ok());
  EXPECT_NE(read.message().find("not a regular file"), std::string::npos) << read.message();
  EXPECT_FALSE(check_exr_file(fifo).ok());
}

// Runs write_exr in a child after `restrict_child` (a file-size limit, dropped privileges...);
// returns the child's message. The restriction stays in the child: this process is unaffected.
std::string write_in_restricted_child(const std::string& file, const ExrFrame& frame,
                                      const std::function<bool()>& restrict_child,
                                      bool* child_reported_error) {
  int fds[2];
  if (::pipe(fds) != 0) return "pipe failed";
  const pid_t pid = ::fork();
  if (pid < 0) return "fork failed";
  if (pid == 0) {
    ::close(fds[0]);
    if (!restrict_child()) ::_exit(3);
    const Status s = write_exr(file, frame);
    const std::string& message = s.message();
    if (::write(fds[1], message.data(), message.size()) < 0) ::_exit(4);
    ::_exit(s.ok() ? 1 : 0);
  }
  ::close(fds[1]);
  std::string message;
  char buffer[512];
  for (;;) {
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n > 0) {
      message.append(buffer, static_cast<size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  *child_reported_error = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  return message;
}

std::string write_in_size_limited_child(const std::string& file, const ExrFrame& frame,
                                        rlim_t limit, bool* child_reported_error) {
  return write_in_restricted_child(file, frame, [limit] {
    // Without this the kernel kills the writer with SIGXFSZ instead of failing with EFBIG.
    ::signal(SIGXFSZ, SIG_IGN);
    const struct rlimit rl = {limit, limit};
    return ::setrlimit(RLIMIT_FSIZE, &rl) == 0;
  }, child_reported_error);
}

TEST_F(ImageFilesAtomic, FileSizeLimitReportsErrorAndLeavesNoFile) {
  TestFrame data(64, 64);  // noise: far above the 4 KiB limit even ZIP-compressed
  const std::string file = path("frame.exr");
  bool child_reported_error = false;
  const std::string message =
      write_in_size_limited_child(file, data.frame(), 4096, &child_reported_error);
  EXPECT_TRUE(child_reported_error) << message;
  EXPECT_NE(message.find(file), std::string::npos) << message;
  EXPECT_NE(message.find(std::strerror(EFBIG)), std::string::npos) << message;
  EXPECT_TRUE(list_dir(dir_).empty());  // neither the target nor a temporary
}

TEST_F(ImageFilesAtomic, FileSizeLimitKeepsPreviousContent) {
  TestFrame data(64, 64);
  const std::string file = path("frame.exr");
  write_text(file, "previous frame");
  bool child_reported_error = false;
  const std::string message =
      write_in_size_limited_child(file, data.frame(), 4096, &child_reported_error);
  EXPECT_TRUE(child_reported_error) << message;
  EXPECT_EQ(read_text(file), "previous frame");
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"frame.exr"});
}

TEST_F(ImageFilesAtomic, RefusesDirectoryTargetAndLeavesItUntouched) {
  TestFrame data(4, 4);
  const std::string target = path("frame.exr");
  ASSERT_TRUE(fs::create_directory(target));
  write_text(target + "/keep.txt", "kept");
  const Status s = write_exr(target, data.frame());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(target), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("is a directory"), std::string::npos) << s.message();
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_EQ(read_text(target + "/keep.txt"), "kept");
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"frame.exr"});
}

TEST_F(ImageFilesAtomic, RefusesFifoTargetAndLeavesItUntouched) {
  TestFrame data(4, 4);
  const std::string target = path("frame.exr");
  ASSERT_EQ(::mkfifo(target.c_str(), 0600), 0) << std::strerror(errno);
  const Status s = write_exr(target, data.frame());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(target), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("FIFO"), std::string::npos) << s.message();
  struct stat st {};
  ASSERT_EQ(::lstat(target.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"frame.exr"});

  const Status png = write_png(target, data.width, data.height, data.rgba.data());
  EXPECT_FALSE(png.ok());
  ASSERT_EQ(::lstat(target.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

TEST_F(ImageFilesAtomic, RefusesSymlinkTarget) {
  TestFrame data(4, 4);
  const std::string real = path("real.exr");
  write_text(real, "real");
  const std::string link = path("frame.exr");
  fs::create_symlink(real, link);
  const Status s = write_exr(link, data.frame());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("symbolic link"), std::string::npos) << s.message();
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(read_text(real), "real");
  EXPECT_EQ(list_dir(dir_), (std::vector<std::string>{"frame.exr", "real.exr"}));
}

TEST_F(ImageFilesAtomic, MissingFolderIsNamedInTheError) {
  TestFrame data(4, 4);
  const std::string folder = path("missing");
  const std::string target = folder + "/frame.exr";
  const Status s = write_exr(target, data.frame());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'" + folder + "' does not exist"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find(target), std::string::npos) << s.message();
  EXPECT_FALSE(fs::exists(folder));

  write_text(path("plain"), "x");
  const Status not_folder = write_exr(path("plain") + "/frame.exr", data.frame());
  EXPECT_FALSE(not_folder.ok());
  EXPECT_NE(not_folder.message().find("is not a folder"), std::string::npos)
      << not_folder.message();
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"plain"});
}

TEST_F(ImageFilesAtomic, UnwritableFolderIsReported) {
  TestFrame data(4, 4);
  const std::string folder = path("readonly");
  ASSERT_TRUE(fs::create_directory(folder));
  ASSERT_EQ(::chmod(folder.c_str(), 0555), 0);
  // Root ignores folder permissions, so a root test process writes as nobody in a child.
  bool child_reported_error = false;
  const std::string message = write_in_restricted_child(folder + "/frame.exr", data.frame(), [] {
    return ::geteuid() != 0 || (::setgid(65534) == 0 && ::setuid(65534) == 0);
  }, &child_reported_error);
  ::chmod(folder.c_str(), 0755);
  EXPECT_TRUE(child_reported_error) << message;
  EXPECT_NE(message.find(std::strerror(EACCES)), std::string::npos) << message;
  EXPECT_TRUE(list_dir(folder).empty());
}

TEST_F(ImageFilesAtomic, OverwritesExistingRegularFile) {
  TestFrame data(8, 8);
  const std::string file = path("frame.exr");
  write_text(file, "stale content that is not an EXR");
  ExrFrame first = data.frame();
  ASSERT_TRUE(write_exr(file, first).ok());
  ExrFrame second = data.frame();
  second.metadata.frame = 43;
  const Status s = write_exr(file, second);
  ASSERT_TRUE(s.ok()) << s.message();

  ExrImage image;
  const Status read = read_exr(file, &image);
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(image.metadata.frame, 43);
  EXPECT_EQ(*image.find("depth.Z"), data.depth);
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"frame.exr"});
}

TEST_F(ImageFilesAtomic, RelativePathAndFolderPathAreHandled) {
  TestFrame data(4, 4);
  const Status folder_path = write_exr(dir_ + "/", data.frame());
  EXPECT_FALSE(folder_path.ok());
  EXPECT_NE(folder_path.message().find("names a folder"), std::string::npos)
      << folder_path.message();
  EXPECT_FALSE(write_exr("", data.frame()).ok());

  const fs::path previous = fs::current_path();
  fs::current_path(dir_);
  const Status relative = write_exr("relative.exr", data.frame());
  fs::current_path(previous);
  EXPECT_TRUE(relative.ok()) << relative.message();
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"relative.exr"});
}

struct DecodedPng {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  bool has_alpha = false;
  std::vector<unsigned char> rgba;  // always 4 channels after decoding
};

bool decode_png(const std::string& file, DecodedPng* out) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, file.c_str())) return false;
  out->width = image.width;
  out->height = image.height;
  out->has_alpha = (image.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  image.format = PNG_FORMAT_RGBA;
  out->rgba.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out->rgba.data(), 0, nullptr)) {
    png_image_free(&image);
    return false;
  }
  return true;
}

// Independent sRGB reference: IEC 61966-2-1 in double precision.
int srgb8(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  const double e = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::lround(e * 255.0));
}

TEST_F(ImageFilesPng, RoundTripIsSrgbEncodedAndClamped) {
  const int width = 5;
  const int height = 3;
  std::vector<float> rgba(static_cast<size_t>(width * height) * 4, 0.0f);
  auto pixel = [&](int x, int y) { return rgba.data() + (static_cast<size_t>(y) * width + x) * 4; };
  float* p = pixel(2, 1);
  p[0] = 0.5f;
  p[1] = 0.18f;
  p[2] = 0.002f;
  p[3] = 0.5f;
  float* q = pixel(4, 2);
  q[0] = 2.0f;
  q[1] = -1.0f;
  q[2] = std::numeric_limits<float>::quiet_NaN();
  q[3] = 7.0f;
  const std::string file = path("preview.png");
  const Status s = write_png(file, width, height, rgba.data(), PngChannels::kRgba);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(list_dir(dir_), std::vector<std::string>{"preview.png"});

  DecodedPng png;
  ASSERT_TRUE(decode_png(file, &png));
  EXPECT_EQ(png.width, 5u);
  EXPECT_EQ(png.height, 3u);
  EXPECT_TRUE(png.has_alpha);
  const unsigned char* a = png.rgba.data() + (1 * width + 2) * 4;
  EXPECT_EQ(a[0], 188);  // sRGB(0.5) = 0.7354
  EXPECT_EQ(a[1], 118);  // sRGB(0.18) = 0.4613
  EXPECT_EQ(a[2], 7);    // linear segment: 12.92 * 0.002
  EXPECT_EQ(a[3], 128);  // alpha stays linear
  EXPECT_EQ(a[0], srgb8(0.5));
  EXPECT_EQ(a[1], srgb8(0.18));
  const unsigned char* b = png.rgba.data() + (2 * width + 4) * 4;
  EXPECT_EQ(b[0], 255);
  EXPECT_EQ(b[1], 0);
  EXPECT_EQ(b[2], 0);  // NaN → 0
  EXPECT_EQ(b[3], 255);
  const unsigned char* origin = png.rgba.data();
  EXPECT_EQ(origin[0], 0);
  EXPECT_EQ(origin[3], 0);
}

TEST_F(ImageFilesPng, RgbPreviewHasNoAlphaAndMatchesReference) {
  const int width = 3;
  const int height = 2;
  std::vector<float> rgba(static_cast<size_t>(width * height) * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<float>(i) / 24.0f;
  const std::string file = path("preview.png");
  ASSERT_TRUE(write_png(file, width, height, rgba.data(), PngChannels::kRgb).ok());

  DecodedPng png;
  ASSERT_TRUE(decode_png(file, &png));
  EXPECT_FALSE(png.has_alpha);
  for (size_t i = 0; i < static_cast<size_t>(width * height); ++i) {
    for (size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(png.rgba[i * 4 + c], srgb8(rgba[i * 4 + c])) << i << " " << c;
    }
    EXPECT_EQ(png.rgba[i * 4 + 3], 255);  // decoder fills the missing alpha
  }
}

TEST_F(ImageFilesPng, ErrorsNameThePathAndLeaveNoFile) {
  std::vector<float> rgba(16, 0.25f);
  const std::string missing = path("missing") + "/preview.png";
  Status s = write_png(missing, 2, 2, rgba.data());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(missing), std::string::npos) << s.message();
  s = write_png(path("preview.png"), 0, 2, rgba.data());
  EXPECT_FALSE(s.ok());
  s = write_png(path("preview.png"), 2, 2, nullptr);
  EXPECT_FALSE(s.ok());
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(encode_png(2, 2, rgba.data(), PngChannels::kRgba, &bytes).ok());
  EXPECT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes[1], 'P');  // PNG signature \x89PNG
  EXPECT_TRUE(list_dir(dir_).empty());
}

TEST_F(ImageFilesPng, LibpngErrorIsReportedWithoutLeaking) {
  // libpng refuses widths above its default user limit (1,000,000): exercises the longjmp path.
  const int width = 1000001;
  std::vector<float> rgba(static_cast<size_t>(width) * 4, 0.5f);
  const std::string file = path("wide.png");
  const Status s = write_png(file, width, 1, rgba.data());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find(file), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("width"), std::string::npos) << s.message();
  EXPECT_TRUE(list_dir(dir_).empty());
}

}  // namespace
}  // namespace siviflow
