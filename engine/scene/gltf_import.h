// Hardened glTF 2.0 / GLB import through tinygltf (reliability.md §3.2 and §5 rows 1-12, 30).
//
// tinygltf 2.7.0 accepts many invalid files and crashes on deeply nested JSON, so this importer
// reads the file itself (regular file, size cap), checks the GLB container and the JSON nesting
// depth before tinygltf sees the bytes, confines every external file tinygltf asks for to the
// folder of the glTF file, keeps images encoded (never decodes them), and then range-checks
// every accessor, bufferView and buffer it reads. Every error message starts with the file and
// names the object that is wrong (accessor, bufferView, mesh, primitive, node, vertex, ...).
//
// Thread-safe: no global state; two loads may run at the same time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "siviflow/status.h"

namespace siviflow {

class Sha256;

// --- Limits: every cap of the importer, in one place ------------------------------------------
// The .gltf/.glb file itself (tinygltf takes a 32-bit length; the JSON DOM costs ~10x the text).
inline constexpr size_t kMaxGltfFileBytes = size_t{256} << 20;
// One external file a glTF references (.bin buffer or image), and all of them together.
inline constexpr size_t kMaxGltfExternalFileBytes = size_t{256} << 20;
inline constexpr size_t kMaxGltfExternalTotalBytes = size_t{1} << 30;
// JSON nesting depth: tinygltf's recursive JSON->Value conversion overflows the stack at ~20k
// levels inside `extras`; real glTF files nest fewer than 10 levels.
inline constexpr size_t kMaxGltfJsonDepth = 64;
// Vertices and indices of one load (all primitives together), checked before allocating.
inline constexpr size_t kMaxGltfVertices = size_t{1} << 26;
inline constexpr size_t kMaxGltfIndices = size_t{3} << 26;
// One encoded image, and the decoded extent a base-colour texture may have (read from the
// PNG/JPEG header, so a decoder is never asked to allocate more than this).
inline constexpr size_t kMaxGltfImageBytes = size_t{64} << 20;
inline constexpr uint32_t kMaxGltfImageDimension = 8192;

// The river's water surface: one triangle primitive, in world space.
struct TriangleMesh {
  // The primitive's vertices in the file's accessor order (the order of `siviflow flow` rows),
  // transformed by the global transform of the first node that instances the mesh.
  std::vector<glm::vec3> positions;
  // Three per triangle, as written; 0, 1, 2, ... when the primitive is not indexed.
  std::vector<uint32_t> indices;
  std::string mesh_name;  // the mesh that was loaded
  int mesh_index = -1;
  int node_index = -1;  // the node whose transform was applied; -1: identity (no node)
};

// An image kept encoded (PNG or JPEG bytes as stored in the file): decoding, with the extent cap
// above, is the caller's separate step.
struct GltfImage {
  std::vector<uint8_t> encoded;
  std::string mime_type;  // "image/png" or "image/jpeg", sniffed from the bytes
  uint32_t width = 0;     // read from the PNG/JPEG header, <= kMaxGltfImageDimension
  uint32_t height = 0;
  int source_index = -1;  // index in the glTF's `images`
};

// One triangle primitive of a scene object, in the object's space (node transforms applied).
struct GltfPrimitive {
  std::string label;  // "mesh 'Duck' primitive 0 (node 3)", for messages
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;     // unit; computed (area-weighted) when the file has none
  std::vector<glm::vec2> texcoords;   // empty when the primitive has no texture coordinates
  std::vector<uint32_t> indices;      // counter-clockwise triangles (mirrored nodes re-wound)
  glm::vec4 base_color_factor{1.0f};  // linear RGBA
  int base_color_image = -1;          // index into GltfObject::images; -1: none
};

struct GltfObject {
  std::vector<GltfPrimitive> primitives;
  std::vector<GltfImage> images;  // the base-colour images the primitives use, each once
  glm::vec3 bounds_min{0.0f};     // of every position, for footprints and culling
  glm::vec3 bounds_max{0.0f};
  size_t dropped_triangles = 0;  // degenerate (repeated index or zero area), left out
  size_t skipped_instances = 0;  // mesh instances under a singular (zero-scale) node
};

// Loads the river's water surface from `path` (.gltf or .glb): the mesh named `mesh_name`
// (empty: the first mesh), which must have exactly one TRIANGLES primitive with a float VEC3
// POSITION. Indices, when present, must be unsigned 8/16/32-bit, in range and a multiple of 3.
// Degenerate triangles are kept (the river surface builder names them). `out` is left
// untouched on failure.
Status load_river_mesh(const std::string& path, const std::string& mesh_name, TriangleMesh* out);

// Loads every TRIANGLES primitive that the default scene instances (scene 0 when none is marked
// default; every mesh once, untransformed, when the file has no scenes and no nodes), with the
// node transforms applied, normals (computed when absent), TEXCOORD_n of the base-colour texture
// (else TEXCOORD_0 when present), the base-colour factor and the base-colour image kept encoded.
// Fails when nothing drawable is left. `out` is left untouched on failure.
Status load_gltf_object(const std::string& path, GltfObject* out);

// Adds to `content` every byte that loading `path` reads, each file as its length (8 bytes,
// little-endian) then its bytes: the file, then each external buffer and image in the order the
// loader reads them (embedded data is in the file). What a capture records its scene's content by.
// Fails where a load would fail to read or parse the file.
Status hash_gltf_content(const std::string& path, Sha256* content);

// Reads the width and height from a PNG or JPEG header without decoding; `what` names the image
// in the message. Fails on any other format or a truncated header.
Status read_image_extent(std::span<const uint8_t> encoded, const std::string& what, uint32_t* width,
                         uint32_t* height);

// Reads a whole regular file (no FIFO, device or directory) of at most `max_bytes`. Shared by
// the scene-file loader.
Status read_regular_file(const std::string& path, size_t max_bytes, std::string* out);

}  // namespace siviflow
