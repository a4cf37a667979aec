// Lookup of the SPIR-V modules embedded at build time (see cmake/siviflow_shaders.cmake).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace siviflow {

struct ShaderBlob {
  std::string_view name;  // file name in shaders/, e.g. "scene.vert"
  const uint32_t* words;
  size_t word_count;
};

// The embedded module of that file name, or nullptr.
const ShaderBlob* find_shader(std::string_view name);

}  // namespace siviflow
