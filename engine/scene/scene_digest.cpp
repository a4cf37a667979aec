#include "siviflow/scene_digest.h"

#include <exception>
#include <set>

#include "scene/gltf_import.h"
#include "siviflow/sha256.h"
#include "siviflow/text_format.h"
#include "siviflow/version.h"

namespace siviflow {
namespace {

constexpr const char* kDigestPrefix = "sha256:";
// Leads every message hashed, so that a later way of digesting a scene never matches this one.
constexpr const char* kDigestFormat = "siviflow scene content 1\n";

Status digest(const SceneFile* scene, std::string* out) {
  Sha256 content;
  content.update(kDigestFormat);
  if (scene == nullptr) {
    content.update(std::string("built-in default scene of ") + version_string());
    *out = kDigestPrefix + hex_digest(content.finish());
    return Status::success();
  }
  content.update("scene " + scene->text_sha256 + "\n");
  std::set<std::string> hashed;  // a file several rivers or objects use counts once
  const auto add = [&](const std::string& gltf, const std::string& where) {
    if (!hashed.insert(gltf).second) return Status::success();
    const Status status = hash_gltf_content(gltf, &content);
    if (status.ok()) return status;
    return Status::error(scene->path + ": " + where + ": " + status.message(), status.code());
  };
  for (size_t i = 0; i < scene->rivers.size(); ++i) {
    const SceneRiver& river = scene->rivers[i];
    if (river.source == SceneRiver::Source::kGltf) {
      SIVIFLOW_TRY(add(river.gltf, text_format("rivers[%zu]", i)));
    }
  }
  for (size_t i = 0; i < scene->objects.size(); ++i) {
    SIVIFLOW_TRY(add(scene->objects[i].gltf, text_format("objects[%zu]", i)));
  }
  *out = kDigestPrefix + hex_digest(content.finish());
  return Status::success();
}

}  // namespace

Status scene_content_digest(const SceneFile* scene, std::string* out) {
  try {
    return digest(scene, out);
  } catch (const std::exception& e) {  // std::bad_alloc holding a file
    return Status::error(std::string("cannot digest the scene: ") + e.what());
  }
}

}  // namespace siviflow
