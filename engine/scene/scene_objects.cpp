#include "scene/scene_objects.h"

#include <map>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "scene/gltf_import.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

struct LoadedFile {
  GltfObject object;
  std::vector<int> textures;  // per image of the file: its index in SceneObjects::textures, or -1
};

}  // namespace

Status load_scene_objects(const SceneFile& scene, SceneObjects* out) {
  SceneObjects result;
  result.textures.push_back(white_base_color());
  size_t texture_bytes = result.textures[0].texels.size();
  std::map<std::string, LoadedFile> files;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& so = scene.objects[i];
    const std::string where = scene.path + text_format(": objects[%zu]: ", i);
    auto [file, inserted] = files.try_emplace(so.gltf);
    if (inserted) {
      const Status loaded = load_gltf_object(so.gltf, &file->second.object);  // names the file
      if (!loaded.ok()) return Status::error(where + loaded.message(), loaded.code());
      file->second.textures.assign(file->second.object.images.size(), -1);
    }
    LoadedFile& loaded = file->second;
    for (const GltfPrimitive& primitive : loaded.object.primitives) {
      uint32_t texture = 0;
      if (primitive.base_color_image >= 0 && !primitive.texcoords.empty()) {
        int& slot = loaded.textures[static_cast<size_t>(primitive.base_color_image)];
        if (slot < 0) {
          const GltfImage& image = loaded.object.images[static_cast<size_t>(primitive.base_color_image)];
          BaseColorTexture decoded;
          const std::string what = text_format("%s: image %d", so.gltf.c_str(), image.source_index);
          const Status status = decode_base_color(image, what, &decoded);
          if (!status.ok()) return Status::error(where + status.message());
          texture_bytes += decoded.texels.size();
          if (texture_bytes > kMaxSceneTextureBytes) {
            return Status::error(where + text_format(
                "%s: the scene's textures would take more than %zu MiB decoded", what.c_str(),
                kMaxSceneTextureBytes >> 20));
          }
          slot = static_cast<int>(result.textures.size());
          result.textures.push_back(std::move(decoded));
        }
        texture = static_cast<uint32_t>(slot);
      }
      if (result.vertices.size() + primitive.positions.size() > kMaxGltfVertices ||
          result.indices.size() + primitive.indices.size() > kMaxGltfIndices) {
        return Status::error(where + text_format(
            "%s: the scene's objects together have more than %zu vertices or %zu indices",
            so.gltf.c_str(), kMaxGltfVertices, kMaxGltfIndices));
      }
      const auto base = static_cast<uint32_t>(result.vertices.size());
      for (size_t v = 0; v < primitive.positions.size(); ++v) {
        gpu::SceneVertex vertex{};
        // glTF order: scale, then rotate, then translate; normals by the inverse transpose.
        vertex.position = so.translation + so.rotation * (so.scale * primitive.positions[v]);
        if (!within_world(vertex.position)) {
          return Status::error(where + text_format("%s: vertex %zu placed by the object's "
                                                   "translation, rotation and scale ",
                                                   so.gltf.c_str(), v) +
                               world_limit_problem(vertex.position));
        }
        vertex.normal = glm::normalize(so.rotation * (primitive.normals[v] / so.scale));
        vertex.color = glm::vec4(glm::vec3(primitive.base_color_factor), 1.0f);
        if (!primitive.texcoords.empty()) vertex.texcoord = primitive.texcoords[v];
        result.vertices.push_back(vertex);
      }
      SceneObjects::Draw draw;
      draw.first_index = static_cast<uint32_t>(result.indices.size());
      draw.index_count = static_cast<uint32_t>(primitive.indices.size());
      draw.texture = texture;
      for (uint32_t index : primitive.indices) result.indices.push_back(base + index);
      result.draws.push_back(draw);
    }
  }
  *out = std::move(result);
  return Status::success();
}

}  // namespace siviflow
