// glTF files written by tests: a straight river channel and boxes (plain, or textured with a
// base-colour image beside them), each as .gltf with an external .bin.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace siviflow::testing {

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Writes the buffers back to back into `gltf` with a .bin extension; returns their offsets.
template <typename... Arrays>
std::vector<size_t> write_bin(const std::filesystem::path& gltf, const Arrays&... arrays) {
  std::ofstream bin(std::filesystem::path(gltf).replace_extension(".bin"), std::ios::binary);
  std::vector<size_t> offsets;
  size_t at = 0;
  const auto put = [&](const auto& array) {
    offsets.push_back(at);
    const size_t bytes = array.size() * sizeof(array[0]);
    bin.write(reinterpret_cast<const char*>(array.data()), static_cast<std::streamsize>(bytes));
    at += bytes;
  };
  (put(arrays), ...);
  offsets.push_back(at);
  return offsets;
}

// A river surface of any shape (mesh "River"), as glTF with a .bin.
inline void write_river_gltf(const std::filesystem::path& gltf, const std::vector<glm::vec3>& points,
                             const std::vector<uint32_t>& indices) {
  std::vector<float> positions;
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : points) {
    positions.insert(positions.end(), {p.x, p.y, p.z});
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const std::vector<size_t> at = write_bin(gltf, positions, indices);
  std::ostringstream json;
  json << R"({"asset":{"version":"2.0"},"meshes":[{"name":"River","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
       << R"("buffers":[{"uri":")" << std::filesystem::path(gltf).replace_extension(".bin").filename().string()
       << R"(","byteLength":)" << at[2] << "}],"
       << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << at[1]
       << R"(},{"buffer":0,"byteOffset":)" << at[1] << R"(,"byteLength":)" << at[2] - at[1] << "}],"
       << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << points.size()
       << R"(,"type":"VEC3","min":[)" << lo.x << "," << lo.y << "," << lo.z << "],\"max\":[" << hi.x << ","
       << hi.y << "," << hi.z << "]},"
       << R"({"bufferView":1,"componentType":5125,"count":)" << indices.size() << R"(,"type":"SCALAR"}]})";
  write_text(gltf, json.str());
}

// A straight channel along +Z, `across` vertices per section, width w, as glTF with a .bin;
// with a `drop` it descends that many metres per metre downstream; its centreline at x = `x`.
inline void write_channel_gltf(const std::filesystem::path& gltf, int sections, int across,
                               float width, float spacing, float drop = 0.0f, float x = 0.0f) {
  std::vector<glm::vec3> positions;
  for (int k = 0; k < sections; ++k) {
    for (int j = 0; j < across; ++j) {
      positions.push_back({x + width * 0.5f - width * static_cast<float>(j) / (across - 1),  // left = +X
                           -drop * spacing * static_cast<float>(k), spacing * static_cast<float>(k)});
    }
  }
  std::vector<uint32_t> indices;
  for (int k = 0; k + 1 < sections; ++k) {
    for (int j = 0; j + 1 < across; ++j) {
      const uint32_t a = k * across + j, b = a + 1, c = a + across, d = c + 1;
      indices.insert(indices.end(), {a, c, b, b, c, d});
    }
  }
  write_river_gltf(gltf, positions, indices);
}

// An axis-aligned box from -half to +half (12 triangles, indexed), as glTF with a .bin.
inline void write_box_gltf(const std::filesystem::path& gltf, const glm::vec3& half) {
  std::vector<float> positions;
  for (int i = 0; i < 8; ++i) {
    positions.push_back((i & 1) ? half.x : -half.x);
    positions.push_back((i & 2) ? half.y : -half.y);
    positions.push_back((i & 4) ? half.z : -half.z);
  }
  const std::vector<uint16_t> indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6,   // -z, +z
                                         0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7,   // -y, +y
                                         0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};  // -x, +x
  const std::vector<size_t> at = write_bin(gltf, positions, indices);
  std::ostringstream json;
  json << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
       << R"("meshes":[{"name":"Box","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
       << R"("buffers":[{"uri":")" << std::filesystem::path(gltf).replace_extension(".bin").filename().string()
       << R"(","byteLength":)" << at[2] << "}],"
       << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << at[1]
       << R"(},{"buffer":0,"byteOffset":)" << at[1] << R"(,"byteLength":)" << at[2] - at[1] << "}],"
       << R"("accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[)"
       << -half.x << "," << -half.y << "," << -half.z << "],\"max\":[" << half.x << "," << half.y
       << "," << half.z << "]},"
       << R"({"bufferView":1,"componentType":5123,"count":)" << indices.size() << R"(,"type":"SCALAR"}]})";
  write_text(gltf, json.str());
}

// A box whose six faces each show the whole of `image` (a file name beside the glTF, PNG or
// JPEG), times `factor`: 24 vertices with TEXCOORD_0, normals left to the importer.
inline void write_textured_box_gltf(const std::filesystem::path& gltf, const glm::vec3& half,
                                    const std::string& image, const glm::vec4& factor) {
  std::vector<float> positions;
  std::vector<float> texcoords;
  std::vector<uint16_t> indices;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      const int u_axis = (axis + 1) % 3;
      const int v_axis = (axis + 2) % 3;
      const auto base = static_cast<uint16_t>(positions.size() / 3);
      for (int corner = 0; corner < 4; ++corner) {
        const float u = (corner & 1) ? 1.0f : 0.0f;
        const float v = (corner & 2) ? 1.0f : 0.0f;
        glm::vec3 p(0.0f);
        p[axis] = static_cast<float>(sign) * half[axis];
        p[u_axis] = (2.0f * u - 1.0f) * half[u_axis];
        p[v_axis] = (2.0f * v - 1.0f) * half[v_axis];
        positions.insert(positions.end(), {p.x, p.y, p.z});
        texcoords.insert(texcoords.end(), {u, v});
      }
      // Counter-clockwise seen from outside the box.
      if (sign > 0) {
        indices.insert(indices.end(), {base, uint16_t(base + 1), uint16_t(base + 3), base,
                                       uint16_t(base + 3), uint16_t(base + 2)});
      } else {
        indices.insert(indices.end(), {base, uint16_t(base + 3), uint16_t(base + 1), base,
                                       uint16_t(base + 2), uint16_t(base + 3)});
      }
    }
  }
  const std::vector<size_t> at = write_bin(gltf, positions, texcoords, indices);
  std::ostringstream json;
  json << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
       << R"("meshes":[{"name":"Box","primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],)"
       << R"("materials":[{"pbrMetallicRoughness":{"baseColorFactor":[)" << factor.r << ","
       << factor.g << "," << factor.b << "," << factor.a << R"(],"baseColorTexture":{"index":0}}}],)"
       << R"("textures":[{"source":0}],"images":[{"uri":")" << image << R"("}],)"
       << R"("buffers":[{"uri":")" << std::filesystem::path(gltf).replace_extension(".bin").filename().string()
       << R"(","byteLength":)" << at[3] << "}],"
       << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << at[1]
       << R"(},{"buffer":0,"byteOffset":)" << at[1] << R"(,"byteLength":)" << at[2] - at[1]
       << R"(},{"buffer":0,"byteOffset":)" << at[2] << R"(,"byteLength":)" << at[3] - at[2] << "}],"
       << R"("accessors":[{"bufferView":0,"componentType":5126,"count":24,"type":"VEC3","min":[)"
       << -half.x << "," << -half.y << "," << -half.z << "],\"max\":[" << half.x << "," << half.y
       << "," << half.z << "]},"
       << R"({"bufferView":1,"componentType":5126,"count":24,"type":"VEC2"},)"
       << R"({"bufferView":2,"componentType":5123,"count":)" << indices.size() << R"(,"type":"SCALAR"}]})";
  write_text(gltf, json.str());
}

}  // namespace siviflow::testing
