// glTF import: a good strip in every container, then every bad input of reliability.md §5 rows
// 1-12 and 30 that concerns the importer (rows 13-15, strip topology, are RiverSurface's). Each
// bad input must fail with a message naming the file and the problem, never crash or hang.
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/gltf_import.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr int kByte = 5120;
constexpr int kUnsignedByte = 5121;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kFloat = 5126;

// A fresh folder per test: ctest runs tests in parallel processes.
fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::path(SIVIFLOW_BINARY_DIR) / "test_tmp" / "gltf_import" /
                       (std::string(info->test_suite_name()) + "." + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir / "models");
  return dir;
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

std::string base64(const std::string& in) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (i < in.size()) {
    uint32_t v = uint8_t(in[i]) << 16;
    if (i + 1 < in.size()) v |= uint8_t(in[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < in.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

void put_le32(std::string* s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

// A GLB container around `json` and `bin` (each padded to 4 bytes as the spec asks).
std::string make_glb(std::string json, std::string bin) {
  while (json.size() % 4) json.push_back(' ');
  while (bin.size() % 4) bin.push_back('\0');
  std::string out;
  put_le32(&out, 0x46546C67u);
  put_le32(&out, 2);
  put_le32(&out, static_cast<uint32_t>(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
  put_le32(&out, static_cast<uint32_t>(json.size()));
  put_le32(&out, 0x4E4F534Au);
  out += json;
  if (!bin.empty()) {
    put_le32(&out, static_cast<uint32_t>(bin.size()));
    put_le32(&out, 0x004E4942u);
    out += bin;
  }
  return out;
}

// Builds glTF documents with one buffer whose bytes live in `bin`.
struct GltfBuilder {
  Json doc = {{"asset", {{"version", "2.0"}}}};
  std::string bin;

  int view(const void* data, size_t n, size_t stride = 0) {
    while (bin.size() % 4) bin.push_back('\0');
    Json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", n}};
    if (stride) v["byteStride"] = stride;
    bin.append(static_cast<const char*>(data), n);
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int accessor(int view_index, int component_type, size_t count, const char* type,
               bool normalized = false) {
    Json a = {{"bufferView", view_index},
              {"componentType", component_type},
              {"count", count},
              {"type", type}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  int positions(const std::vector<glm::vec3>& p) {
    return accessor(view(p.data(), p.size() * sizeof(glm::vec3)), kFloat, p.size(), "VEC3");
  }
  template <typename T>
  int indices(const std::vector<T>& i, int component_type) {
    return accessor(view(i.data(), i.size() * sizeof(T)), component_type, i.size(), "SCALAR");
  }
  int mesh(const std::string& name, const Json& primitive) {
    doc["meshes"].push_back({{"name", name}, {"primitives", Json::array({primitive})}});
    return static_cast<int>(doc["meshes"].size()) - 1;
  }
  int node(const Json& n) {
    doc["nodes"].push_back(n);
    return static_cast<int>(doc["nodes"].size()) - 1;
  }
  static Json triangles(int position, int index_accessor) {
    Json p = {{"attributes", {{"POSITION", position}}}, {"mode", 4}};
    if (index_accessor >= 0) p["indices"] = index_accessor;
    return p;
  }
  Json with_buffer(const Json& buffer) const {
    Json d = doc;
    d["buffers"] = Json::array({buffer});
    return d;
  }
  Json with_data_uri() const {
    return with_buffer({{"byteLength", bin.size()},
                        {"uri", "data:application/octet-stream;base64," + base64(bin)}});
  }
  Json with_external(const std::string& uri) const {
    return with_buffer({{"byteLength", bin.size()}, {"uri", uri}});
  }
  std::string glb() const {
    return make_glb(with_buffer({{"byteLength", bin.size()}}).dump(), bin);
  }
};

// The strip: 2 sections x 3 vertices, written in a scrambled order (vertex 0 is a corner).
const std::vector<glm::vec3> kStripPositions = {{0, 0, 0}, {2, 0, 1}, {1, 0, 0},
                                                {0, 0, 1}, {2, 0, 0}, {1, 0, 1}};
const std::vector<uint16_t> kStripIndices = {0, 3, 2, 2, 3, 5, 2, 5, 4, 4, 5, 1};

// Parent node: translate (10, 0, -5) and turn 90 degrees about +Y; child: scale 2, the mesh.
glm::vec3 strip_world(const glm::vec3& p) {
  return glm::vec3(2 * p.z, 2 * p.y, -2 * p.x) + glm::vec3(10, 0, -5);
}

GltfBuilder strip_builder(const std::string& name = "River") {
  GltfBuilder b;
  const int pos = b.positions(kStripPositions);
  const int idx = b.indices(kStripIndices, kUnsignedShort);
  const int mesh = b.mesh(name, GltfBuilder::triangles(pos, idx));
  const float h = std::sqrt(0.5f);
  b.node({{"name", "Parent"},
          {"translation", {10, 0, -5}},
          {"rotation", {0, h, 0, h}},
          {"children", {1}}});
  b.node({{"name", "Child"}, {"scale", {2, 2, 2}}, {"mesh", mesh}});
  b.doc["scenes"] = Json::array({{{"nodes", {0}}}});
  b.doc["scene"] = 0;
  return b;
}

void expect_strip(const TriangleMesh& mesh) {
  ASSERT_EQ(mesh.positions.size(), kStripPositions.size());
  for (size_t i = 0; i < kStripPositions.size(); ++i) {
    const glm::vec3 want = strip_world(kStripPositions[i]);
    EXPECT_NEAR(mesh.positions[i].x, want.x, 1e-5) << "vertex " << i;
    EXPECT_NEAR(mesh.positions[i].y, want.y, 1e-5) << "vertex " << i;
    EXPECT_NEAR(mesh.positions[i].z, want.z, 1e-5) << "vertex " << i;
  }
  EXPECT_EQ(mesh.indices, std::vector<uint32_t>(kStripIndices.begin(), kStripIndices.end()));
  EXPECT_EQ(mesh.mesh_name, "River");
  EXPECT_EQ(mesh.node_index, 1);
}

// The load fails and the message names the file and every part of the problem.
void expect_refused(const Status& status, const std::string& file_name,
                    std::initializer_list<std::string> parts) {
  ASSERT_FALSE(status.ok()) << "expected a failure for " << file_name;
  EXPECT_NE(status.message().find(file_name), std::string::npos) << status.message();
  for (const std::string& part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << "missing '" << part << "' in: " << status.message();
  }
}

Status load_text(const fs::path& dir, const std::string& name, const std::string& text,
                 TriangleMesh* mesh) {
  write_file(dir / name, text);
  return load_river_mesh((dir / name).string(), "", mesh);
}

Status load_json(const fs::path& dir, const Json& doc, TriangleMesh* mesh,
                 const std::string& name = "river.gltf") {
  return load_text(dir, name, doc.dump(), mesh);
}

// ------------------------------------------------------------------------------------------------
// Good files.

TEST(GltfImport, StripFromGlbKeepsAccessorOrderAndAppliesTheNodeTransform) {
  const fs::path dir = test_dir();
  write_file(dir / "river.glb", strip_builder().glb());
  TriangleMesh mesh;
  const Status status = load_river_mesh((dir / "river.glb").string(), "", &mesh);
  ASSERT_TRUE(status.ok()) << status.message();
  expect_strip(mesh);
}

TEST(GltfImport, StripFromGltfWithExternalBin) {
  const fs::path dir = test_dir();
  const GltfBuilder b = strip_builder();
  write_file(dir / "models" / "river.bin", b.bin);
  write_file(dir / "models" / "river.gltf", b.with_external("river.bin").dump());
  TriangleMesh mesh;
  const Status status = load_river_mesh((dir / "models" / "river.gltf").string(), "River", &mesh);
  ASSERT_TRUE(status.ok()) << status.message();
  expect_strip(mesh);
}

TEST(GltfImport, NonIndexedStripFromDataUriWithoutNodes) {
  const fs::path dir = test_dir();
  GltfBuilder b;
  std::vector<glm::vec3> soup;
  for (const uint16_t i : kStripIndices) soup.push_back(kStripPositions[i]);
  b.mesh("River", GltfBuilder::triangles(b.positions(soup), -1));
  TriangleMesh mesh;
  const Status status = load_json(dir, b.with_data_uri(), &mesh);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(mesh.positions.size(), soup.size());
  for (size_t i = 0; i < soup.size(); ++i)
    EXPECT_EQ(mesh.positions[i], soup[i]) << "identity without a node";
  ASSERT_EQ(mesh.indices.size(), soup.size());
  for (size_t i = 0; i < soup.size(); ++i) EXPECT_EQ(mesh.indices[i], i);
  EXPECT_EQ(mesh.node_index, -1);
}

TEST(GltfImport, SelectsTheMeshByName) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder("Bank");
  std::vector<glm::vec3> moved = kStripPositions;
  for (glm::vec3& p : moved) p.y += 3.0f;
  const int pos = b.positions(moved);
  b.mesh("River", GltfBuilder::triangles(pos, b.indices(kStripIndices, kUnsignedShort)));
  write_file(dir / "two.glb", b.glb());
  TriangleMesh mesh;
  Status status = load_river_mesh((dir / "two.glb").string(), "River", &mesh);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(mesh.mesh_index, 1);
  EXPECT_EQ(mesh.positions[0], glm::vec3(0, 3, 0)) << "no node instances mesh 1: identity";

  status = load_river_mesh((dir / "two.glb").string(), "Rivr", &mesh);
  expect_refused(status, "two.glb", {"no mesh named 'Rivr'", "'Bank', 'River'"});
}

TEST(GltfImport, RiverMeshWithTwoPrimitivesIsRefused) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder();
  b.doc["meshes"][0]["primitives"].push_back(b.doc["meshes"][0]["primitives"][0]);
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"mesh 'River' has 2 primitives"});
}

TEST(GltfImport, FailureLeavesTheOutputUntouched) {
  const fs::path dir = test_dir();
  TriangleMesh mesh;
  mesh.positions = {glm::vec3(7.0f)};
  ASSERT_FALSE(load_text(dir, "bad.gltf", "{", &mesh).ok());
  ASSERT_EQ(mesh.positions.size(), 1u);
  EXPECT_EQ(mesh.positions[0], glm::vec3(7.0f));
}

// ------------------------------------------------------------------------------------------------
// Row 1: empty, truncated, non-JSON, non-object root, binary garbage.

TEST(GltfImportBad, Row1EmptyFile) {
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "empty.gltf", "", &mesh), "empty.gltf", {"empty"});
}

TEST(GltfImportBad, Row1TruncatedJson) {
  const std::string full = strip_builder().with_data_uri().dump();
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "cut.gltf", full.substr(0, full.size() / 2), &mesh),
                 "cut.gltf", {"not a valid glTF", "parse"});
}

TEST(GltfImportBad, Row1NotJson) {
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "prose.gltf", "this is not json", &mesh), "prose.gltf",
                 {"not a valid glTF"});
}

TEST(GltfImportBad, Row1RootNotAnObject) {
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "array.gltf", "[1, 2, 3]", &mesh), "array.gltf",
                 {"not a valid glTF"});
}

TEST(GltfImportBad, Row1BinaryGarbage) {
  std::string garbage;
  for (int i = 0; i < 4096; ++i) garbage.push_back(static_cast<char>((i * 7919 + 13) & 0xFF));
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "noise.gltf", garbage, &mesh), "noise.gltf",
                 {"not a valid glTF"});
}

// ------------------------------------------------------------------------------------------------
// Row 2: GLB container errors.

TEST(GltfImportBad, Row2GlbBadMagic) {
  std::string glb = strip_builder().glb();
  glb[0] = 'X';
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "magic.glb", glb, &mesh), "magic.glb", {"bad GLB magic"});
}

TEST(GltfImportBad, Row2GlbTruncated) {
  const std::string glb = strip_builder().glb();
  TriangleMesh mesh;
  const fs::path dir = test_dir();
  expect_refused(load_text(dir, "short.glb", glb.substr(0, 7), &mesh), "short.glb",
                 {"GLB header truncated"});
  expect_refused(load_text(dir, "cut.glb", glb.substr(0, glb.size() - 16), &mesh), "cut.glb",
                 {"GLB header says the file is"});
}

TEST(GltfImportBad, Row2GlbChunkLengthPastTheFile) {
  std::string glb = strip_builder().glb();
  std::string length;
  put_le32(&length, 1u << 30);
  glb.replace(12, 4, length);
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "chunk.glb", glb, &mesh), "chunk.glb",
                 {"chunk 0 length 1073741824 runs past"});
}

TEST(GltfImportBad, Row2GlbTotalLengthLies) {
  std::string glb = strip_builder().glb();
  std::string length;
  put_le32(&length, static_cast<uint32_t>(glb.size() - 8));
  glb.replace(8, 4, length);
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "liar.glb", glb, &mesh), "liar.glb",
                 {"GLB header says the file is"});
}

TEST(GltfImportBad, Row2GlbUnalignedJsonChunk) {
  const GltfBuilder b = strip_builder();
  std::string json = b.with_buffer({{"byteLength", b.bin.size()}}).dump();
  while (json.size() % 4 != 1) json.push_back(' ');
  std::string glb;
  put_le32(&glb, 0x46546C67u);
  put_le32(&glb, 2);
  put_le32(&glb, static_cast<uint32_t>(12 + 8 + json.size() + 8 + b.bin.size()));
  put_le32(&glb, static_cast<uint32_t>(json.size()));
  put_le32(&glb, 0x4E4F534Au);
  glb += json;
  put_le32(&glb, static_cast<uint32_t>(b.bin.size()));
  put_le32(&glb, 0x004E4942u);
  glb += b.bin;
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "unaligned.glb", glb, &mesh), "unaligned.glb",
                 {"not a multiple of 4"});
}

TEST(GltfImportBad, Row2GlbHeaderOnly) {
  std::string glb;
  put_le32(&glb, 0x46546C67u);
  put_le32(&glb, 2);
  put_le32(&glb, 12);
  TriangleMesh mesh;
  expect_refused(load_text(test_dir(), "header.glb", glb, &mesh), "header.glb", {"no JSON chunk"});
}

// ------------------------------------------------------------------------------------------------
// Row 3: deep nesting crashes tinygltf 2.7.0 (stack overflow); it must not reach it.

TEST(GltfImportBad, Row3DeepNestingInExtrasIsRefusedBeforeTinygltf) {
  const GltfBuilder b = strip_builder();
  std::string json = b.with_data_uri().dump();
  json.pop_back();  // the closing brace
  json += ",\"extras\":" + std::string(20000, '[') + std::string(20000, ']') + "}";
  const fs::path dir = test_dir();
  TriangleMesh mesh;
  expect_refused(load_text(dir, "deep.gltf", json, &mesh), "deep.gltf",
                 {"nested deeper than 64 levels", "refused before parsing"});
  expect_refused(load_text(dir, "deep.glb", make_glb(json, ""), &mesh), "deep.glb",
                 {"nested deeper than 64"});
}

TEST(GltfImportBad, Row3BracketsInsideStringsDoNotCount) {
  GltfBuilder b = strip_builder();
  b.doc["extras"] = {{"note", std::string(500, '[')}};
  TriangleMesh mesh;
  const Status status = load_json(test_dir(), b.with_data_uri(), &mesh);
  EXPECT_TRUE(status.ok()) << status.message();
}

// ------------------------------------------------------------------------------------------------
// Row 4: external files: missing, outside the folder, absolute, schemes, not regular.

TEST(GltfImportBad, Row4MissingBin) {
  const fs::path dir = test_dir();
  TriangleMesh mesh;
  expect_refused(load_json(dir, strip_builder().with_external("missing.bin"), &mesh), "river.gltf",
                 {"missing.bin", "does not exist"});
}

TEST(GltfImportBad, Row4TraversalIsRefused) {
  const fs::path dir = test_dir();
  const GltfBuilder b = strip_builder();
  write_file(dir / "outside.bin", b.bin);  // the right size: only containment stops it
  write_file(dir / "models" / "river.gltf", b.with_external("../outside.bin").dump());
  TriangleMesh mesh;
  expect_refused(load_river_mesh((dir / "models" / "river.gltf").string(), "", &mesh), "river.gltf",
                 {"'../outside.bin' resolves outside the glTF's folder"});
  // Percent-encoded dots are decoded by tinygltf and still refused.
  write_file(dir / "models" / "encoded.gltf", b.with_external("%2e%2e/outside.bin").dump());
  expect_refused(load_river_mesh((dir / "models" / "encoded.gltf").string(), "", &mesh),
                 "encoded.gltf", {"resolves outside"});
}

TEST(GltfImportBad, Row4SymlinkLeavingTheFolderIsRefused) {
  const fs::path dir = test_dir();
  const GltfBuilder b = strip_builder();
  write_file(dir / "outside.bin", b.bin);
  fs::create_symlink(dir / "outside.bin", dir / "models" / "link.bin");
  write_file(dir / "models" / "river.gltf", b.with_external("link.bin").dump());
  TriangleMesh mesh;
  expect_refused(load_river_mesh((dir / "models" / "river.gltf").string(), "", &mesh), "river.gltf",
                 {"'link.bin' resolves outside"});
}

TEST(GltfImportBad, Row4AbsoluteAndFileUrisAreRefused) {
  const fs::path dir = test_dir();
  const GltfBuilder b = strip_builder();
  write_file(dir / "models" / "river.bin", b.bin);
  const std::string absolute = (dir / "models" / "river.bin").string();
  TriangleMesh mesh;
  expect_refused(load_json(dir / "models", b.with_external(absolute), &mesh), "river.gltf",
                 {"is an absolute path"});
  expect_refused(load_json(dir / "models", b.with_external("file://" + absolute), &mesh),
                 "river.gltf", {"has a scheme"});
}

TEST(GltfImportBad, Row4FifoAndDirectoryAreRefused) {
  const fs::path dir = test_dir();
  const GltfBuilder b = strip_builder();
  ASSERT_EQ(::mkfifo((dir / "pipe.bin").c_str(), 0600), 0);
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_external("pipe.bin"), &mesh), "river.gltf",
                 {"'pipe.bin' is not a regular file"});
  expect_refused(load_json(dir, b.with_external("models"), &mesh), "river.gltf",
                 {"'models' is not a regular file"});
  // The glTF itself must be a regular file too (a FIFO would block a plain read forever).
  expect_refused(load_river_mesh((dir / "pipe.bin").string(), "", &mesh), "pipe.bin",
                 {"not a regular file"});
}

// ------------------------------------------------------------------------------------------------
// Row 5: data URIs.

TEST(GltfImportBad, Row5BadBase64) {
  const GltfBuilder b = strip_builder();
  TriangleMesh mesh;
  const Json doc = b.with_buffer(
      {{"byteLength", b.bin.size()}, {"uri", "data:application/octet-stream;base64,@@@@"}});
  expect_refused(load_json(test_dir(), doc, &mesh), "river.gltf", {"not a valid glTF"});
}

TEST(GltfImportBad, Row5ByteLengthMismatchAndZero) {
  const fs::path dir = test_dir();
  const GltfBuilder b = strip_builder();
  Json doc = b.with_data_uri();
  doc["buffers"][0]["byteLength"] = b.bin.size() + 4;
  TriangleMesh mesh;
  expect_refused(load_json(dir, doc, &mesh), "river.gltf", {"not a valid glTF"});
  doc["buffers"][0]["byteLength"] = 0;
  expect_refused(load_json(dir, doc, &mesh), "river.gltf", {"not a valid glTF"});
}

// ------------------------------------------------------------------------------------------------
// Row 6: ranges tinygltf accepts.

TEST(GltfImportBad, Row6AccessorCountPastItsBufferView) {
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["count"] = 7;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"accessor 0 (POSITION of mesh 'River' primitive 0): count 7",
                  "exceeds its bufferView 0 (byteLength 72)"});
}

TEST(GltfImportBad, Row6AccessorOffsetPastItsBufferView) {
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["byteOffset"] = 4;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"accessor 0 (POSITION", "byteOffset 4", "exceeds its bufferView 0"});
}

TEST(GltfImportBad, Row6BufferViewPastItsBuffer) {
  GltfBuilder b = strip_builder();
  b.doc["bufferViews"][1]["byteLength"] = 4000;
  TriangleMesh mesh;
  expect_refused(
      load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
      {"bufferView 1 (byteOffset 72, byteLength 4000", "runs past the end of buffer 0 (96 bytes)"});
}

TEST(GltfImportBad, Row6BufferViewIndexOutOfRange) {
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["bufferView"] = 9;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"accessor 0 (POSITION", "bufferView 9 does not exist"});
}

TEST(GltfImportBad, Row6AttributeAccessorIndexOutOfRange) {
  GltfBuilder b = strip_builder();
  b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 42;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"POSITION of mesh 'River' primitive 0 refers to accessor 42", "has 2 accessors"});
}

TEST(GltfImportBad, Row6StrideSmallerThanAnElement) {
  GltfBuilder b = strip_builder();
  b.doc["bufferViews"][0]["byteStride"] = 8;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"byteStride 8, less than one element"});
}

TEST(GltfImportBad, Row6StridedPositionsAreReadCorrectly) {
  GltfBuilder b;
  std::vector<float> interleaved;  // position + 1 float of padding per vertex
  for (const glm::vec3& p : kStripPositions)
    interleaved.insert(interleaved.end(), {p.x, p.y, p.z, -1.0f});
  const int view = b.view(interleaved.data(), interleaved.size() * sizeof(float), 16);
  const int pos = b.accessor(view, kFloat, kStripPositions.size(), "VEC3");
  b.mesh("River", GltfBuilder::triangles(pos, b.indices(kStripIndices, kUnsignedShort)));
  TriangleMesh mesh;
  const Status status = load_json(test_dir(), b.with_data_uri(), &mesh);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(mesh.positions, kStripPositions);
}

// ------------------------------------------------------------------------------------------------
// Row 7: wrong accessor types.

TEST(GltfImportBad, Row7PositionVec2) {
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["type"] = "VEC2";
  TriangleMesh mesh;
  expect_refused(
      load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
      {"accessor 0 (POSITION of mesh 'River' primitive 0): is FLOAT VEC2, expected FLOAT VEC3"});
}

TEST(GltfImportBad, Row7PositionUnsignedByteOrNormalized) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["componentType"] = kUnsignedByte;
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"is UNSIGNED_BYTE VEC3, expected FLOAT VEC3"});
  b.doc["accessors"][0]["componentType"] = kUnsignedShort;
  b.doc["accessors"][0]["normalized"] = true;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"is normalized UNSIGNED_SHORT VEC3"});
}

TEST(GltfImportBad, Row7IndicesFloatOrSigned) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder();
  b.doc["accessors"][1]["componentType"] = kFloat;
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"accessor 1 (indices of mesh 'River' primitive 0): is FLOAT SCALAR"});
  b.doc["accessors"][1]["componentType"] = kByte;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf", {"is BYTE SCALAR"});
}

TEST(GltfImportBad, Row7UnknownComponentTypeOrType) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["componentType"] = 9999;
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf", {"not a valid glTF"});
  b = strip_builder();
  b.doc["accessors"][0]["type"] = "VEC5";
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf", {"not a valid glTF"});
}

// ------------------------------------------------------------------------------------------------
// Row 8: counts.

TEST(GltfImportBad, Row8HugeCountIsCaughtBeforeAllocating) {
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["count"] = uint64_t{1} << 62;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"accessor 0 (POSITION of mesh 'River' primitive 0): count 4611686018427387904",
                  "exceeds its bufferView 0 (byteLength 72)"});
}

TEST(GltfImportBad, Row8NegativeOrStringCount) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder();
  b.doc["accessors"][0]["count"] = -6;
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf", {"not a valid glTF"});
  b.doc["accessors"][0]["count"] = "6";
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf", {"not a valid glTF"});
}

// ------------------------------------------------------------------------------------------------
// Row 9: structure tinygltf accepts.

TEST(GltfImportBad, Row9NoPosition) {
  GltfBuilder b = strip_builder();
  b.doc["meshes"][0]["primitives"][0]["attributes"] = {{"NORMAL", 0}};
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"mesh 'River' primitive 0: has no POSITION attribute"});
}

TEST(GltfImportBad, Row9ModeLines) {
  GltfBuilder b = strip_builder();
  b.doc["meshes"][0]["primitives"][0]["mode"] = 1;
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"mesh 'River' primitive 0: mode is LINES (1); only TRIANGLES (4)"});
}

TEST(GltfImportBad, Row9NoMeshes) {
  GltfBuilder b = strip_builder();
  b.doc.erase("meshes");
  b.doc["nodes"][1].erase("mesh");
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf", {"has no meshes"});
}

TEST(GltfImportBad, Row9SparseAccessor) {
  GltfBuilder b = strip_builder();
  const uint16_t sparse_indices[] = {1};
  const float sparse_values[] = {5, 5, 5};
  const int iv = b.view(sparse_indices, sizeof(sparse_indices));
  const int vv = b.view(sparse_values, sizeof(sparse_values));
  b.doc["accessors"][0]["sparse"] = {
      {"count", 1},
      {"indices", {{"bufferView", iv}, {"componentType", kUnsignedShort}}},
      {"values", {{"bufferView", vv}}}};
  TriangleMesh mesh;
  expect_refused(
      load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
      {"accessor 0 (POSITION of mesh 'River' primitive 0): sparse accessors are not supported"});
}

TEST(GltfImportBad, Row9DracoOrMeshoptRequired) {
  const fs::path dir = test_dir();
  for (const char* ext : {"KHR_draco_mesh_compression", "EXT_meshopt_compression"}) {
    GltfBuilder b = strip_builder();
    b.doc["extensionsUsed"] = {ext};
    b.doc["extensionsRequired"] = {ext};
    TriangleMesh mesh;
    expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                   {std::string("extensionsRequired lists '") + ext + "'", "without compression"});
  }
}

TEST(GltfImportBad, Row9AssetVersion1) {
  GltfBuilder b = strip_builder();
  b.doc["asset"]["version"] = "1.0";
  TriangleMesh mesh;
  expect_refused(load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
                 {"asset.version is '1.0'"});
}

// ------------------------------------------------------------------------------------------------
// Row 10: indices.

TEST(GltfImportBad, Row10IndexOutOfRange) {
  GltfBuilder b;
  std::vector<uint32_t> indices(kStripIndices.begin(), kStripIndices.end());
  indices[7] = 6;
  const int pos = b.positions(kStripPositions);
  b.mesh("River", GltfBuilder::triangles(pos, b.indices(indices, kUnsignedInt)));
  TriangleMesh mesh;
  expect_refused(
      load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
      {"accessor 1 (indices of mesh 'River' primitive 0): index 7 (triangle 2) is 6, but the "
       "primitive has 6 vertices"});
}

TEST(GltfImportBad, Row10IndexCountNotAMultipleOfThree) {
  GltfBuilder b;
  std::vector<uint8_t> indices(kStripIndices.begin(), kStripIndices.end() - 1);
  const int pos = b.positions(kStripPositions);
  b.mesh("River", GltfBuilder::triangles(pos, b.indices(indices, kUnsignedByte)));
  TriangleMesh mesh;
  expect_refused(
      load_json(test_dir(), b.with_data_uri(), &mesh), "river.gltf",
      {"accessor 1 (indices of mesh 'River' primitive 0): 11 indices is not a multiple of 3"});
}

// ------------------------------------------------------------------------------------------------
// Row 11: non-finite positions, named by vertex.

TEST(GltfImportBad, Row11NanOrInfPositionNamesTheVertex) {
  const fs::path dir = test_dir();
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    std::vector<glm::vec3> positions = kStripPositions;
    positions[4].y = bad;
    GltfBuilder b;
    const int pos = b.positions(positions);
    b.mesh("River", GltfBuilder::triangles(pos, b.indices(kStripIndices, kUnsignedShort)));
    TriangleMesh mesh;
    expect_refused(
        load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
        {"accessor 0 (POSITION of mesh 'River' primitive 0): vertex 4 has a non-finite position"});
  }
}

TEST(GltfImportBad, NodeHierarchyErrors) {
  const fs::path dir = test_dir();
  GltfBuilder b = strip_builder();
  b.doc["nodes"][1]["children"] = {0};  // 0 -> 1 -> 0
  TriangleMesh mesh;
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"the node hierarchy has a cycle"});
  b = strip_builder();
  b.doc["nodes"][0]["children"] = {1, 7};
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"node 0: child 7 does not exist"});
  b = strip_builder();
  b.doc["nodes"][0]["rotation"] = {0, 0, 0};
  expect_refused(load_json(dir, b.with_data_uri(), &mesh), "river.gltf",
                 {"node 0: rotation has 3 numbers"});
}

// ------------------------------------------------------------------------------------------------
// Scene objects: transforms, normals, texture coordinates, materials, images (row 30).

// A PNG signature and IHDR of the given extent, and nothing decodable after it: loading must
// keep it as bytes (a decoder would fail on it).
std::string fake_png(uint32_t width, uint32_t height) {
  std::string png = "\x89PNG\r\n\x1a\n";
  png += std::string("\0\0\0\x0dIHDR", 8);
  for (const uint32_t v : {width, height}) {
    for (int s = 24; s >= 0; s -= 8) png.push_back(static_cast<char>((v >> s) & 0xFF));
  }
  png += std::string("\x08\x06\0\0\0\xde\xad\xbe\xef", 9);
  return png;
}

// A unit quad in the XZ plane facing +Y, with u16 normalized UVs and a textured material, placed
// by two nodes: one moved by +5 X, one mirrored in X.
GltfBuilder quad_object_builder(const std::string& png) {
  GltfBuilder b;
  const std::vector<glm::vec3> positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}};
  const std::vector<uint16_t> uvs = {0, 0, 0, 65535, 65535, 65535, 65535, 0};
  const std::vector<uint16_t> indices = {0, 1, 3, 1, 2, 3};
  const int pos = b.positions(positions);
  const int uv = b.accessor(b.view(uvs.data(), uvs.size() * 2), kUnsignedShort, 4, "VEC2",
                            /*normalized=*/true);
  const int idx = b.indices(indices, kUnsignedShort);
  const int image_view = b.view(png.data(), png.size());
  Json prim = GltfBuilder::triangles(pos, idx);
  prim["attributes"]["TEXCOORD_0"] = uv;
  prim["material"] = 0;
  b.mesh("Quad", prim);
  b.doc["materials"] = Json::array(
      {{{"pbrMetallicRoughness",
         {{"baseColorFactor", {0.5, 0.25, 1.0, 1.0}}, {"baseColorTexture", {{"index", 0}}}}}}});
  b.doc["textures"] = Json::array({{{"source", 0}}});
  b.doc["images"] = Json::array({{{"bufferView", image_view}, {"mimeType", "image/png"}}});
  b.node({{"mesh", 0}, {"translation", {5, 0, 0}}});
  b.node({{"mesh", 0}, {"scale", {-1, 1, 1}}});
  b.doc["scenes"] = Json::array({{{"nodes", {0, 1}}}});
  b.doc["scene"] = 0;
  return b;
}

Status load_object_json(const fs::path& dir, const Json& doc, GltfObject* object,
                        const std::string& name = "duck.gltf") {
  write_file(dir / name, doc.dump());
  return load_gltf_object((dir / name).string(), object);
}

TEST(GltfObject, LoadsTransformsNormalsTexcoordsMaterialAndKeepsTheImageEncoded) {
  const fs::path dir = test_dir();
  const std::string png = fake_png(4, 2);
  const GltfBuilder b = quad_object_builder(png);
  write_file(dir / "duck.glb", b.glb());
  GltfObject object;
  const Status status = load_gltf_object((dir / "duck.glb").string(), &object);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(object.primitives.size(), 2u);
  ASSERT_EQ(object.images.size(), 1u) << "one image, shared by both instances";
  const GltfImage& image = object.images[0];
  EXPECT_EQ(std::string(image.encoded.begin(), image.encoded.end()), png)
      << "kept as stored, not decoded";
  EXPECT_EQ(image.mime_type, "image/png");
  EXPECT_EQ(image.width, 4u);
  EXPECT_EQ(image.height, 2u);

  const GltfPrimitive& moved = object.primitives[0];
  EXPECT_EQ(moved.positions[2], glm::vec3(6, 0, 1));
  EXPECT_EQ(moved.indices, (std::vector<uint32_t>{0, 1, 3, 1, 2, 3}));
  ASSERT_EQ(moved.texcoords.size(), 4u);
  EXPECT_EQ(moved.texcoords[1], glm::vec2(0, 1));
  EXPECT_EQ(moved.texcoords[2], glm::vec2(1, 1));
  EXPECT_EQ(moved.base_color_factor, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
  EXPECT_EQ(moved.base_color_image, 0);
  for (const glm::vec3& n : moved.normals)
    EXPECT_EQ(n, glm::vec3(0, 1, 0)) << "computed from the faces";

  const GltfPrimitive& mirrored = object.primitives[1];
  EXPECT_EQ(mirrored.positions[2], glm::vec3(-1, 0, 1));
  EXPECT_EQ(mirrored.indices, (std::vector<uint32_t>{0, 3, 1, 1, 3, 2}))
      << "re-wound: still counter-clockwise";
  for (const glm::vec3& n : mirrored.normals) EXPECT_EQ(n, glm::vec3(0, 1, 0));
  EXPECT_EQ(object.bounds_min, glm::vec3(-1, 0, 0));
  EXPECT_EQ(object.bounds_max, glm::vec3(6, 0, 1));
}

TEST(GltfObject, GivenNormalsAreTransformedAndUnit) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  const std::vector<glm::vec3> normals(4, glm::vec3(0, 2, 0));
  b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] =
      b.accessor(b.view(normals.data(), 48), kFloat, 4, "VEC3");
  b.doc["nodes"][0]["rotation"] = {0, 0, std::sqrt(0.5),
                                   std::sqrt(0.5)};  // 90 degrees about +Z: +Y -> -X
  GltfObject object;
  const Status status = load_object_json(test_dir(), b.with_data_uri(), &object);
  ASSERT_TRUE(status.ok()) << status.message();
  const glm::vec3 n = object.primitives[0].normals[0];
  EXPECT_NEAR(n.x, -1.0f, 1e-6f);
  EXPECT_NEAR(n.y, 0.0f, 1e-6f);
  EXPECT_NEAR(n.z, 0.0f, 1e-6f);
}

TEST(GltfObject, Row12DegenerateTrianglesAreDroppedAndCounted) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  const std::vector<uint16_t> indices = {0, 1, 3, 1, 1, 2, 1, 2, 3, 0, 0, 0};
  b.doc["meshes"][0]["primitives"][0]["indices"] = b.indices(indices, kUnsignedShort);
  b.doc["scenes"][0]["nodes"] = {0};
  GltfObject object;
  const Status status = load_object_json(test_dir(), b.with_data_uri(), &object);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(object.dropped_triangles, 2u);
  EXPECT_EQ(object.primitives[0].indices, (std::vector<uint32_t>{0, 1, 3, 1, 2, 3}));
}

TEST(GltfObject, ZeroScaleInstancesAreSkipped) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc["nodes"][1]["scale"] = {0, 0, 0};
  GltfObject object;
  const Status status = load_object_json(test_dir(), b.with_data_uri(), &object);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(object.primitives.size(), 1u);
  EXPECT_EQ(object.skipped_instances, 1u);
}

TEST(GltfObject, Row30ImageExtentIsCappedBeforeAnyDecoding) {
  const GltfBuilder b = quad_object_builder(fake_png(100000, 2));
  GltfObject object;
  expect_refused(load_object_json(test_dir(), b.with_data_uri(), &object), "duck.gltf",
                 {"image 0 is 100000x2, larger than the limit of 8192x8192"});
}

TEST(GltfObject, Row30ImageThatIsNotPngOrJpegIsRefused) {
  const GltfBuilder b = quad_object_builder("GIF89a and more bytes");
  GltfObject object;
  expect_refused(load_object_json(test_dir(), b.with_data_uri(), &object), "duck.gltf",
                 {"image 0: not a PNG or JPEG"});
}

TEST(GltfObject, Row6ImageBufferViewPastItsBufferIsRefused) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc["bufferViews"][3]["byteLength"] = 1 << 20;  // tinygltf would hand out bytes past the buffer
  GltfObject object;
  expect_refused(load_object_json(test_dir(), b.with_data_uri(), &object), "duck.gltf",
                 {"image 0: bufferView 3", "runs past the end of buffer 0"});
}

TEST(GltfObject, Row4ImageOutsideTheFolderIsRefused) {
  const fs::path dir = test_dir();
  write_file(dir / "secret.png", fake_png(1, 1));
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc["images"][0] = {{"uri", "../secret.png"}};
  GltfObject object;
  expect_refused(
      load_object_json(dir / "models", b.with_data_uri(), &object), "duck.gltf",
      {"image 0", "'../secret.png' could not be read", "resolves outside the glTF's folder"});
}

TEST(GltfObject, ExternalImageInTheFolderIsKept) {
  const fs::path dir = test_dir();
  write_file(dir / "models" / "albedo.png", fake_png(16, 8));
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc["images"][0] = {{"uri", "albedo.png"}};
  GltfObject object;
  const Status status = load_object_json(dir / "models", b.with_data_uri(), &object);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(object.images[0].width, 16u);
  EXPECT_EQ(object.images[0].height, 8u);
}

TEST(GltfObject, MissingTexcoordSetOfTheTextureIsRefused) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 1;
  GltfObject object;
  expect_refused(load_object_json(test_dir(), b.with_data_uri(), &object), "duck.gltf",
                 {"mesh 'Quad' primitive 0", "uses TEXCOORD_1, which it lacks"});
}

TEST(GltfObject, NodeReachedTwiceIsRefused) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc["scenes"][0]["nodes"] = {0, 1, 0};
  GltfObject object;
  expect_refused(load_object_json(test_dir(), b.with_data_uri(), &object), "duck.gltf",
                 {"node 0 is reached twice"});
}

TEST(GltfObject, FileWithoutScenesOrNodesUsesEveryMeshOnce) {
  GltfBuilder b = quad_object_builder(fake_png(1, 1));
  b.doc.erase("nodes");
  b.doc.erase("scenes");
  b.doc.erase("scene");
  GltfObject object;
  const Status status = load_object_json(test_dir(), b.with_data_uri(), &object);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(object.primitives.size(), 1u);
  EXPECT_EQ(object.primitives[0].positions[2], glm::vec3(1, 0, 1));
}

TEST(GltfImageExtent, PngAndJpegHeaders) {
  uint32_t w = 0;
  uint32_t h = 0;
  const std::string png = fake_png(640, 480);
  ASSERT_TRUE(
      read_image_extent({reinterpret_cast<const uint8_t*>(png.data()), png.size()}, "png", &w, &h)
          .ok());
  EXPECT_EQ(w, 640u);
  EXPECT_EQ(h, 480u);
  // SOI, an APP0 segment, fill bytes, then a baseline frame header of 300 x 200 (height first).
  const std::vector<uint8_t> jpeg = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0x4A, 0x46,
                                     0xFF, 0xFF, 0xC0, 0x00, 0x0B, 0x08, 0x00, 0xC8,
                                     0x01, 0x2C, 0x01, 0x01, 0x11, 0x00};
  const Status status = read_image_extent(jpeg, "jpeg", &w, &h);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(w, 300u);
  EXPECT_EQ(h, 200u);
  const std::vector<uint8_t> truncated(jpeg.begin(), jpeg.begin() + 12);
  EXPECT_FALSE(read_image_extent(truncated, "jpeg", &w, &h).ok());
  const std::vector<uint8_t> no_frame = {0xFF, 0xD8, 0xFF, 0xDA, 0x00, 0x02};
  EXPECT_FALSE(read_image_extent(no_frame, "jpeg", &w, &h).ok());
}

}  // namespace
}  // namespace siviflow
