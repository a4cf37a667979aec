// The scene's content digest (scene_content_digest): the same bytes digest alike wherever they lie
// and however the scene's path is spelled; a changed byte in the scene file, a river's buffer or
// an object's image is another digest; a missing glTF file is refused by name.
#include "siviflow/scene_digest.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "gltf_test_files.h"
#include "run_command.h"
#include "siviflow/scene_file.h"
#include "siviflow/sha256.h"
#include "siviflow/version.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;
using testing::write_text;

constexpr const char* kScene = R"({"version": 1, "river": {"gltf": "river.gltf"},
  "objects": [{"gltf": "box.gltf", "translation": [30, 0, 5]}, {"gltf": "box.gltf"}]})";

// A scene of a glTF river and a textured box (each with a .bin; the box with an image) in `dir`.
void write_scene(const fs::path& dir) {
  fs::create_directories(dir);
  testing::write_channel_gltf(dir / "river.gltf", 6, 4, 8.0f, 2.0f);
  testing::write_textured_box_gltf(dir / "box.gltf", glm::vec3(1.0f), "box.png", glm::vec4(1.0f));
  write_text(dir / "box.png", "image bytes: the digest reads them, it does not decode them");
  write_text(dir / "scene.json", kScene);
}

std::string digest_of(const std::string& scene_path) {
  SceneFile scene;
  Status status = load_scene_file(scene_path, &scene);
  EXPECT_TRUE(status.ok()) << status.message();
  std::string digest;
  status = scene_content_digest(&scene, &digest);
  EXPECT_TRUE(status.ok()) << status.message();
  return digest;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(SceneDigest, SameContentAnywhereIsTheSameDigest) {
  const fs::path dir = testing::fresh_test_dir("scene_digest");
  write_scene(dir / "a");
  fs::copy(dir / "a", dir / "b");
  const std::string digest = digest_of((dir / "a" / "scene.json").string());
  ASSERT_EQ(digest.rfind("sha256:", 0), 0u) << digest;
  EXPECT_EQ(digest.size(), 7u + 64u);
  EXPECT_EQ(digest_of((dir / "b" / "scene.json").string()), digest);
  EXPECT_EQ(digest_of((dir / "a" / ".." / "b" / "." / "scene.json").string()), digest);
  const fs::path cwd = fs::current_path();
  ASSERT_EQ(chdir((dir / "a").c_str()), 0);
  EXPECT_EQ(digest_of("scene.json"), digest);
  EXPECT_EQ(digest_of("./scene.json"), digest);
  ASSERT_EQ(chdir(cwd.c_str()), 0);
}

TEST(SceneDigest, EveryFileTheLoaderReadsCounts) {
  const fs::path dir = testing::fresh_test_dir("scene_digest");
  write_scene(dir);
  const std::string scene = (dir / "scene.json").string();
  const std::string original = digest_of(scene);
  for (const char* file :
       {"scene.json", "river.gltf", "river.bin", "box.gltf", "box.bin", "box.png"}) {
    const std::string bytes = read_bytes(dir / file);
    std::string changed = bytes;
    const bool json = fs::path(file).extension() != ".bin" && fs::path(file).extension() != ".png";
    if (json) {
      changed += "\n";  // still the same JSON, but other bytes
    } else {
      changed.back() = static_cast<char>(changed.back() ^ 1);
    }
    write_bytes(dir / file, changed);
    EXPECT_NE(digest_of(scene), original) << file;
    write_bytes(dir / file, bytes);
    EXPECT_EQ(digest_of(scene), original) << file;
  }
  // A file beside the scene that nothing reads does not count.
  write_text(dir / "notes.txt", "not part of the scene");
  EXPECT_EQ(digest_of(scene), original);
}

TEST(SceneDigest, DefaultSceneIsItsNameAndVersion) {
  std::string digest;
  ASSERT_TRUE(scene_content_digest(nullptr, &digest).ok());
  Sha256 expected;
  expected.update("siviflow scene content 1\n");
  expected.update(std::string("built-in default scene of ") + version_string());
  EXPECT_EQ(digest, "sha256:" + hex_digest(expected.finish()));
}

TEST(SceneDigest, MissingGltfIsNamed) {
  const fs::path dir = testing::fresh_test_dir("scene_digest");
  write_scene(dir);
  fs::remove(dir / "box.gltf");
  SceneFile scene;
  ASSERT_TRUE(load_scene_file((dir / "scene.json").string(), &scene).ok());
  std::string digest = "untouched";
  const Status status = scene_content_digest(&scene, &digest);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("scene.json: objects[0]: "), std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("box.gltf"), std::string::npos) << status.message();
  EXPECT_EQ(digest, "untouched");
}

}  // namespace
}  // namespace siviflow
