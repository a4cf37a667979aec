// The glTF objects of a scene file, ready for the scene pass: every primitive of every object
// placed in the world by its node transforms and the object's translation, rotation and scale,
// with its base-colour texture decoded. A file used by several objects is loaded once, and each
// of its images is decoded once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "scene/base_color_texture.h"
#include "shaders/shared.h"
#include "siviflow/scene_file.h"
#include "siviflow/status.h"

namespace siviflow {

// The objects together are held to the importer's caps of one load (kMaxGltfVertices/Indices).
// All decoded base-colour textures of a scene together may take at most this many bytes (mips
// included): a scene of many 8k textures would exhaust a software rasterizer's memory first.
inline constexpr size_t kMaxSceneTextureBytes = size_t{1} << 30;

struct SceneObjects {
  std::vector<gpu::SceneVertex> vertices;  // world space; colour = base-colour factor, AO 1
  std::vector<uint32_t> indices;           // into `vertices`, three per triangle
  struct Draw {
    uint32_t first_index = 0;
    uint32_t index_count = 0;
    uint32_t texture = 0;  // into `textures`
  };
  std::vector<Draw> draws;  // one per primitive
  std::vector<BaseColorTexture> textures;  // [0] is white, for primitives without an image
};

// Loads every object of `scene`. Errors name the scene file, the object and its glTF file.
// `out` is left untouched on failure.
Status load_scene_objects(const SceneFile& scene, SceneObjects* out);

}  // namespace siviflow
