#include "scene/gltf_import.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <numeric>
#include <string_view>
#include <unordered_map>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <tiny_gltf.h>

#include "siviflow/sha256.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// glTF stores little-endian data; we read it with memcpy.
static_assert(std::endian::native == std::endian::little, "the glTF reader assumes little-endian");

constexpr uint32_t kGlbMagic = 0x46546C67u;      // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534Au;  // "JSON"
constexpr uint32_t kGlbChunkBin = 0x004E4942u;   // "BIN\0"
constexpr size_t kGlbHeaderBytes = 12;
constexpr size_t kGlbChunkHeaderBytes = 8;
constexpr size_t kMaxRefusalNotes = 8;  // enough to explain a failure, bounded for hostile files

Status fail(const std::string& file, const std::string& what) {
  return Status::error(file + ": " + what);
}

// --- Files ---------------------------------------------------------------------------------------

struct FdCloser {
  int fd;
  ~FdCloser() { ::close(fd); }
};

// Reads a regular file of at most max_bytes into `out` (std::string or std::vector<uint8_t>).
// no_follow: refuse a symlink as the last component (the path was already resolved).
template <typename Container>
Status read_file_bytes(const std::string& path, size_t max_bytes, bool no_follow, Container* out) {
  const int flags = O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK | (no_follow ? O_NOFOLLOW : 0);
  const int fd = ::open(path.c_str(), flags);  // O_NONBLOCK: opening a FIFO must not hang
  if (fd < 0) {
    return fail(path, text_format("cannot open: %s", std::strerror(errno)));
  }
  FdCloser closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    return fail(path, text_format("cannot stat: %s", std::strerror(errno)));
  }
  if (!S_ISREG(st.st_mode)) {
    return fail(path, "not a regular file (a directory, device or FIFO)");
  }
  if (st.st_size < 0 || static_cast<uint64_t>(st.st_size) > max_bytes) {
    return fail(path, text_format("is %lld bytes, more than the limit of %zu",
                                  static_cast<long long>(st.st_size), max_bytes));
  }
  Container data(static_cast<size_t>(st.st_size), 0);
  size_t got = 0;
  while (got < data.size()) {
    const ssize_t n = ::read(fd, data.data() + got, data.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail(path, text_format("read error: %s", std::strerror(errno)));
    if (n == 0) break;
    got += static_cast<size_t>(n);
  }
  data.resize(got);
  char extra = 0;
  ssize_t n = 0;
  do {
    n = ::read(fd, &extra, 1);
  } while (n < 0 && errno == EINTR);
  if (n > 0) return fail(path, "the file grew while it was being read");
  *out = std::move(data);
  return Status::success();
}

std::string realpath_of(const std::string& path) {
  std::unique_ptr<char, decltype(&std::free)> resolved(::realpath(path.c_str(), nullptr),
                                                       &std::free);
  return resolved ? std::string(resolved.get()) : std::string();
}

bool has_uri_scheme(std::string_view uri) {
  // RFC 3986 scheme: ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":" (also catches "C:").
  if (uri.empty() || !std::isalpha(static_cast<unsigned char>(uri[0]))) return false;
  for (size_t i = 1; i < uri.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(uri[i]);
    if (c == ':') return true;
    if (!std::isalnum(c) && c != '+' && c != '-' && c != '.') return false;
  }
  return false;
}

bool ends_with_ci(std::string_view s, std::string_view suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) !=
        std::tolower(static_cast<unsigned char>(suffix[i]))) {
      return false;
    }
  }
  return true;
}

uint32_t read_le32(const char* p) {
  uint32_t v = 0;
  std::memcpy(&v, p, 4);
  return v;
}

// --- Before tinygltf: container and nesting ------------------------------------------------------

// Offset where the JSON nesting first exceeds max_depth, or npos. Brackets inside strings do not
// count; the text need not be valid JSON (the parser reports that).
size_t find_excess_nesting(std::string_view text, size_t max_depth) {
  size_t depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::string_view::npos;
}

// Checks the 12-byte header and every chunk header of a GLB; `json` receives the JSON chunk.
Status check_glb(const std::string& file, std::string_view bytes, std::string_view* json) {
  if (bytes.size() < kGlbHeaderBytes) {
    return fail(file,
                text_format("GLB header truncated: the file has %zu bytes, the header needs %zu",
                            bytes.size(), kGlbHeaderBytes));
  }
  const uint32_t magic = read_le32(bytes.data());
  if (magic != kGlbMagic) {
    return fail(file,
                text_format("bad GLB magic 0x%08x (expected 0x%08x, \"glTF\")", magic, kGlbMagic));
  }
  const uint32_t version = read_le32(bytes.data() + 4);
  if (version != 2) {
    return fail(file,
                text_format("GLB container version %u (only version 2 is supported)", version));
  }
  const uint32_t length = read_le32(bytes.data() + 8);
  if (length != bytes.size()) {
    return fail(file, text_format("GLB header says the file is %u bytes, but it has %zu", length,
                                  bytes.size()));
  }
  size_t offset = kGlbHeaderBytes;
  for (int chunk = 0; offset < bytes.size(); ++chunk) {
    if (bytes.size() - offset < kGlbChunkHeaderBytes) {
      return fail(file, text_format("GLB chunk %d header truncated at byte %zu", chunk, offset));
    }
    const uint32_t chunk_length = read_le32(bytes.data() + offset);
    const uint32_t chunk_type = read_le32(bytes.data() + offset + 4);
    const size_t data_offset = offset + kGlbChunkHeaderBytes;
    if (chunk_length > bytes.size() - data_offset) {
      return fail(file, text_format("GLB chunk %d length %u runs past the end of the file "
                                    "(%zu bytes left)",
                                    chunk, chunk_length, bytes.size() - data_offset));
    }
    if (chunk_length % 4 != 0) {
      return fail(
          file, text_format("GLB chunk %d length %u is not a multiple of 4", chunk, chunk_length));
    }
    if (chunk == 0) {
      if (chunk_type != kGlbChunkJson) {
        return fail(file, text_format("GLB chunk 0 has type 0x%08x; it must be the JSON chunk",
                                      chunk_type));
      }
      if (chunk_length == 0) return fail(file, "GLB JSON chunk is empty");
      *json = bytes.substr(data_offset, chunk_length);
    } else if (chunk == 1 && chunk_type != kGlbChunkBin) {
      return fail(file,
                  text_format("GLB chunk 1 has type 0x%08x; it must be the BIN chunk", chunk_type));
    }
    offset = data_offset + chunk_length;
  }
  if (offset == kGlbHeaderBytes) return fail(file, "GLB has a header but no JSON chunk");
  return Status::success();
}

// --- tinygltf callbacks --------------------------------------------------------------------------

struct LoadContext {
  std::string base_dir;     // realpath of the glTF's folder
  std::string base_prefix;  // base_dir with a trailing '/'
  size_t external_bytes = 0;
  std::vector<std::string> notes;  // why a file was refused, appended to error messages
  const tinygltf::Model* model = nullptr;
  Sha256* content = nullptr;  // what hash_gltf_content adds every file read to, when asked

  void note(std::string why) {
    if (notes.size() < kMaxRefusalNotes &&
        std::find(notes.begin(), notes.end(), why) == notes.end()) {
      notes.push_back(std::move(why));
    }
  }
};

// One file of a load into `content`: its length first, so that no two lists of files hash alike.
template <typename Container>
void hash_file(const Container& bytes, Sha256* content) {
  uint8_t length[8];
  for (int i = 0; i < 8; ++i) length[i] = static_cast<uint8_t>(uint64_t{bytes.size()} >> (8 * i));
  content->update(length, sizeof length);
  content->update(bytes.data(), bytes.size());
}

// Whether tinygltf may open `joined` (its base_dir + "/" + uri); `real` receives the realpath.
bool allowed_path(LoadContext* ctx, const std::string& joined, std::string* real) {
  // tinygltf retries relative to the working directory ("./uri"): never allowed.
  if (joined.rfind(ctx->base_prefix, 0) != 0) return false;
  const std::string uri = joined.substr(ctx->base_prefix.size());
  if (uri.empty()) return false;
  if (uri[0] == '/' || uri[0] == '\\') {
    ctx->note("uri '" + uri +
              "' is an absolute path; only paths relative to the glTF's folder are allowed");
    return false;
  }
  if (has_uri_scheme(uri)) {
    ctx->note("uri '" + uri +
              "' has a scheme (file:, http:, ...); only relative paths are allowed");
    return false;
  }
  const std::string resolved = realpath_of(joined);
  if (resolved.empty()) {
    ctx->note("uri '" + uri + "' does not exist in " + ctx->base_dir);
    return false;
  }
  if (resolved.rfind(ctx->base_prefix, 0) != 0) {
    ctx->note("uri '" + uri + "' resolves outside the glTF's folder " + ctx->base_dir);
    return false;
  }
  struct stat st {};
  if (::stat(resolved.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
    ctx->note("uri '" + uri + "' is not a regular file");
    return false;
  }
  if (static_cast<uint64_t>(st.st_size) > kMaxGltfExternalFileBytes) {
    ctx->note(text_format("uri '%s' is %lld bytes, more than the limit of %zu", uri.c_str(),
                          static_cast<long long>(st.st_size), kMaxGltfExternalFileBytes));
    return false;
  }
  *real = resolved;
  return true;
}

bool fs_file_exists(const std::string& path, void* user) {
  std::string real;
  return allowed_path(static_cast<LoadContext*>(user), path, &real);
}

std::string fs_expand_file_path(const std::string& path, void*) { return path; }  // no ~ or $VAR

bool fs_read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                        void* user) {
  auto* ctx = static_cast<LoadContext*>(user);
  std::string real;
  if (!allowed_path(ctx, path, &real)) {
    if (err) *err += "refused";
    return false;
  }
  const size_t budget =
      std::min(kMaxGltfExternalFileBytes, kMaxGltfExternalTotalBytes - ctx->external_bytes);
  const Status status = read_file_bytes(real, budget, /*no_follow=*/true, out);
  if (!status.ok()) {
    ctx->note(status.message());
    if (err) *err += status.message();
    return false;
  }
  ctx->external_bytes += out->size();
  if (ctx->content != nullptr) hash_file(*out, ctx->content);
  return true;
}

bool fs_write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&,
                         void*) {
  if (err) *err += "writing files is disabled";
  return false;
}

// The image loader: keeps the encoded bytes, never decodes (stb has a history of decoder bugs;
// reliability.md §3.1). Decoding, with an extent cap, is the renderer's separate step.
bool keep_encoded_image(tinygltf::Image* image, const int image_index, std::string* err,
                        std::string*, int, int, const unsigned char* bytes, int size, void* user) {
  const auto* ctx = static_cast<const LoadContext*>(user);
  auto refuse = [&](const std::string& why) {
    if (err) *err += text_format("image %d: %s\n", image_index, why.c_str());
    return false;
  };
  if (image->bufferView >= 0) {
    // tinygltf hands us &buffer.data[view.byteOffset] and view.byteLength without a range check.
    const tinygltf::Model& m = *ctx->model;
    if (static_cast<size_t>(image->bufferView) >= m.bufferViews.size()) {
      return refuse(text_format("bufferView %d does not exist", image->bufferView));
    }
    const tinygltf::BufferView& view = m.bufferViews[static_cast<size_t>(image->bufferView)];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= m.buffers.size()) {
      return refuse(
          text_format("bufferView %d: buffer %d does not exist", image->bufferView, view.buffer));
    }
    const size_t buffer_size = m.buffers[static_cast<size_t>(view.buffer)].data.size();
    if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset) {
      return refuse(text_format(
          "bufferView %d (byteOffset %zu, byteLength %zu) runs past the end "
          "of buffer %d (%zu bytes)",
          image->bufferView, view.byteOffset, view.byteLength, view.buffer, buffer_size));
    }
    if (size < 0 || static_cast<size_t>(size) != view.byteLength) {
      return refuse(text_format("bufferView %d is too large for an image", image->bufferView));
    }
  }
  if (bytes == nullptr || size <= 0) return refuse("no image bytes");
  if (static_cast<size_t>(size) > kMaxGltfImageBytes) {
    return refuse(
        text_format("%d encoded bytes, more than the limit of %zu", size, kMaxGltfImageBytes));
  }
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (char& c : text) {
    if (c == '\n') c = ';';
  }
  return text;
}

std::string with_notes(std::string message, const std::vector<std::string>& notes) {
  for (const std::string& note : notes) message += "; " + note;
  return message;
}

// Reads, pre-checks and parses `path`; `notes` receives why external files were refused, and
// `content` (when given) every file read (hash_gltf_content).
Status load_model(const std::string& path, tinygltf::Model* model,
                  std::vector<std::string>* notes, Sha256* content = nullptr) {
  std::string bytes;
  SIVIFLOW_TRY(read_file_bytes(path, kMaxGltfFileBytes, /*no_follow=*/false, &bytes));
  if (bytes.empty()) return fail(path, "the file is empty");
  if (content != nullptr) hash_file(bytes, content);
  const bool glb =
      (bytes.size() >= 4 && read_le32(bytes.data()) == kGlbMagic) || ends_with_ci(path, ".glb");
  std::string_view json = bytes;
  if (glb) SIVIFLOW_TRY(check_glb(path, bytes, &json));
  const size_t deep_at = find_excess_nesting(json, kMaxGltfJsonDepth);
  if (deep_at != std::string_view::npos) {
    return fail(path, text_format("JSON nested deeper than %zu levels (at byte %zu of the JSON); "
                                  "refused before parsing",
                                  kMaxGltfJsonDepth, deep_at));
  }

  std::string folder = std::filesystem::path(path).parent_path().string();
  if (folder.empty()) folder = ".";
  LoadContext ctx;
  ctx.base_dir = realpath_of(folder);
  if (ctx.base_dir.empty()) return fail(path, "cannot resolve the folder of the file");
  ctx.base_prefix = ctx.base_dir.back() == '/' ? ctx.base_dir : ctx.base_dir + "/";
  ctx.model = model;
  ctx.content = content;

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&fs_file_exists, &fs_expand_file_path,
                                              &fs_read_whole_file, &fs_write_whole_file, &ctx});
  loader.SetImageLoader(&keep_encoded_image, &ctx);
  std::string err;
  std::string warn;
  bool ok = false;
  try {
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const auto size = static_cast<unsigned int>(bytes.size());  // <= kMaxGltfFileBytes
    ok = glb ? loader.LoadBinaryFromMemory(model, &err, &warn, data, size, ctx.base_dir)
             : loader.LoadASCIIFromString(model, &err, &warn, bytes.data(), size, ctx.base_dir);
  } catch (const std::exception& e) {
    return fail(path, std::string("tinygltf threw: ") + e.what());
  } catch (...) {
    return fail(path, "tinygltf threw an unknown exception");
  }
  *notes = ctx.notes;
  if (!ok) {
    return fail(path,
                with_notes("not a valid glTF: " + (err.empty() ? "(no message)" : one_line(err)),
                           ctx.notes));
  }

  if (model->asset.version.rfind("2.", 0) != 0) {
    return fail(path,
                "asset.version is '" + model->asset.version + "'; only glTF 2.x is supported");
  }
  if (!model->asset.minVersion.empty() && model->asset.minVersion != "2.0") {
    return fail(path,
                "asset.minVersion is '" + model->asset.minVersion + "'; only 2.0 is supported");
  }
  if (!model->extensionsRequired.empty()) {  // no extension a file can require is supported yet
    const std::string& ext = model->extensionsRequired.front();
    const bool compression = ext == "KHR_draco_mesh_compression" ||
                             ext == "EXT_meshopt_compression" || ext == "KHR_mesh_quantization";
    return fail(path,
                "extensionsRequired lists '" + ext + "', which this importer does not support" +
                    (compression ? " (export the mesh without compression or quantization)" : ""));
  }
  return Status::success();
}

// --- Names for messages --------------------------------------------------------------------------

std::string mesh_label(const tinygltf::Model& m, int mesh) {
  const std::string& name = m.meshes[static_cast<size_t>(mesh)].name;
  return name.empty() ? text_format("mesh %d", mesh) : "mesh '" + name + "'";
}

const char* component_name(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT:
      return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE:
      return "DOUBLE";
    default:
      return "an unknown component type";
  }
}

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "an unknown type";
  }
}

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS:
      return "POINTS";
    case TINYGLTF_MODE_LINE:
      return "LINES";
    case TINYGLTF_MODE_LINE_LOOP:
      return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP:
      return "LINE_STRIP";
    case TINYGLTF_MODE_TRIANGLES:
      return "TRIANGLES";
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      return "TRIANGLE_STRIP";
    case TINYGLTF_MODE_TRIANGLE_FAN:
      return "TRIANGLE_FAN";
    default:
      return "unknown";
  }
}

// --- Accessors -----------------------------------------------------------------------------------

enum class Usage { kPosition, kNormal, kTexcoord, kIndices };

struct AccessorData {
  const unsigned char* first = nullptr;  // element 0
  size_t stride = 0;
  size_t count = 0;
  int component_type = 0;
};

bool type_allowed(const tinygltf::Accessor& a, Usage usage) {
  const int ct = a.componentType;
  switch (usage) {
    case Usage::kPosition:
    case Usage::kNormal:
      return a.type == TINYGLTF_TYPE_VEC3 && ct == TINYGLTF_COMPONENT_TYPE_FLOAT && !a.normalized;
    case Usage::kTexcoord:
      return a.type == TINYGLTF_TYPE_VEC2 &&
             ((ct == TINYGLTF_COMPONENT_TYPE_FLOAT && !a.normalized) ||
              ((ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
               a.normalized));
    case Usage::kIndices:
      return a.type == TINYGLTF_TYPE_SCALAR && !a.normalized &&
             (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
              ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
              ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  }
  return false;
}

const char* allowed_types(Usage usage) {
  switch (usage) {
    case Usage::kPosition:
    case Usage::kNormal:
      return "FLOAT VEC3";
    case Usage::kTexcoord:
      return "FLOAT VEC2 or normalized UNSIGNED_BYTE/UNSIGNED_SHORT VEC2";
    case Usage::kIndices:
      return "UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT SCALAR";
  }
  return "";
}

// Resolves accessor `index` for `usage` with every range checked; `what` says what it is for
// ("POSITION of mesh 'River' primitive 0").
Status view_accessor(const std::string& file, const tinygltf::Model& m, int index, Usage usage,
                     const std::string& what, AccessorData* out) {
  if (index < 0 || static_cast<size_t>(index) >= m.accessors.size()) {
    return fail(file, text_format("%s refers to accessor %d, but the file has %zu accessors",
                                  what.c_str(), index, m.accessors.size()));
  }
  const tinygltf::Accessor& a = m.accessors[static_cast<size_t>(index)];
  const std::string name = text_format("accessor %d (%s)", index, what.c_str());
  if (a.sparse.isSparse) {
    return fail(file, name + ": sparse accessors are not supported (apply them in the exporter)");
  }
  if (!type_allowed(a, usage)) {
    return fail(
        file,
        text_format("%s: is %s%s %s, expected %s", name.c_str(), a.normalized ? "normalized " : "",
                    component_name(a.componentType), type_name(a.type), allowed_types(usage)));
  }
  if (a.count == 0) return fail(file, name + ": count is 0");
  if (a.bufferView < 0) {
    return fail(file, name + ": has no bufferView (all zeros), which is not supported here");
  }
  if (static_cast<size_t>(a.bufferView) >= m.bufferViews.size()) {
    return fail(file, text_format("%s: bufferView %d does not exist (the file has %zu)",
                                  name.c_str(), a.bufferView, m.bufferViews.size()));
  }
  const tinygltf::BufferView& view = m.bufferViews[static_cast<size_t>(a.bufferView)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= m.buffers.size()) {
    return fail(
        file, text_format("bufferView %d (used by %s): buffer %d does not exist (the file has %zu)",
                          a.bufferView, name.c_str(), view.buffer, m.buffers.size()));
  }
  const size_t buffer_size = m.buffers[static_cast<size_t>(view.buffer)].data.size();
  if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset) {
    return fail(file, text_format("bufferView %d (byteOffset %zu, byteLength %zu, used by %s) runs "
                                  "past the end of buffer %d (%zu bytes)",
                                  a.bufferView, view.byteOffset, view.byteLength, name.c_str(),
                                  view.buffer, buffer_size));
  }
  const size_t component_bytes = static_cast<size_t>(
      tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType)));
  const size_t element_size =
      component_bytes *
      static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type)));
  const size_t stride = view.byteStride == 0 ? element_size : view.byteStride;
  if (stride < element_size) {
    return fail(file, text_format("%s: its bufferView %d has byteStride %zu, less than one element "
                                  "(%zu bytes)",
                                  name.c_str(), a.bufferView, stride, element_size));
  }
  // byteOffset + stride * (count - 1) + element_size <= view.byteLength, without wrapping.
  size_t end = 0;
  const bool wraps = __builtin_mul_overflow(stride, a.count - 1, &end) ||
                     __builtin_add_overflow(end, element_size, &end) ||
                     __builtin_add_overflow(end, a.byteOffset, &end);
  if (wraps || end > view.byteLength) {
    return fail(
        file,
        text_format("%s: count %zu (byteOffset %zu, stride %zu) exceeds its bufferView "
                    "%d (byteLength %zu)",
                    name.c_str(), a.count, a.byteOffset, stride, a.bufferView, view.byteLength));
  }
  out->first =
      m.buffers[static_cast<size_t>(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
  out->stride = stride;
  out->count = a.count;
  out->component_type = a.componentType;
  return Status::success();
}

template <typename T>
T load_as(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

Status read_vec3s(const std::string& file, const AccessorData& d, const std::string& name,
                  const char* quantity, std::vector<glm::vec3>* out) {
  out->resize(d.count);
  for (size_t i = 0; i < d.count; ++i) {
    const unsigned char* p = d.first + i * d.stride;
    const glm::vec3 v(load_as<float>(p), load_as<float>(p + 4), load_as<float>(p + 8));
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
      return fail(file, text_format("%s: vertex %zu has a non-finite %s (%g, %g, %g)", name.c_str(),
                                    i, quantity, double(v.x), double(v.y), double(v.z)));
    }
    (*out)[i] = v;
  }
  return Status::success();
}

Status read_texcoords(const std::string& file, const AccessorData& d, const std::string& name,
                      std::vector<glm::vec2>* out) {
  out->resize(d.count);
  for (size_t i = 0; i < d.count; ++i) {
    const unsigned char* p = d.first + i * d.stride;
    glm::vec2 uv(0.0f);
    switch (d.component_type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        uv = {load_as<float>(p), load_as<float>(p + 4)};
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        uv = glm::vec2(p[0], p[1]) / 255.0f;
        break;
      default:
        uv = glm::vec2(load_as<uint16_t>(p), load_as<uint16_t>(p + 2)) / 65535.0f;
        break;
    }
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
      return fail(
          file, text_format("%s: vertex %zu has a non-finite texture coordinate", name.c_str(), i));
    }
    (*out)[i] = uv;
  }
  return Status::success();
}

Status read_indices(const std::string& file, const AccessorData& d, const std::string& name,
                    size_t vertex_count, std::vector<uint32_t>* out) {
  if (d.count % 3 != 0) {
    return fail(file, text_format("%s: %zu indices is not a multiple of 3 (a TRIANGLES list)",
                                  name.c_str(), d.count));
  }
  out->resize(d.count);
  for (size_t i = 0; i < d.count; ++i) {
    const unsigned char* p = d.first + i * d.stride;
    uint32_t v = 0;
    switch (d.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        v = p[0];
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        v = load_as<uint16_t>(p);
        break;
      default:
        v = load_as<uint32_t>(p);
        break;
    }
    if (v >= vertex_count) {
      return fail(file, text_format("%s: index %zu (triangle %zu) is %u, but the primitive has %zu "
                                    "vertices",
                                    name.c_str(), i, i / 3, v, vertex_count));
    }
    (*out)[i] = v;
  }
  return Status::success();
}

// One primitive as stored (object space of its mesh).
struct RawPrimitive {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;    // empty: compute
  std::vector<glm::vec2> texcoords;  // empty: none
  std::vector<uint32_t> indices;
};

// texcoord_set < 0: no texture coordinates wanted.
Status read_primitive(const std::string& file, const tinygltf::Model& m, int mesh, int prim,
                      bool want_normals, int texcoord_set, bool texcoords_required,
                      RawPrimitive* out) {
  const tinygltf::Primitive& p =
      m.meshes[static_cast<size_t>(mesh)].primitives[static_cast<size_t>(prim)];
  const std::string label = text_format("%s primitive %d", mesh_label(m, mesh).c_str(), prim);
  if (p.mode != TINYGLTF_MODE_TRIANGLES) {
    return fail(file, text_format("%s: mode is %s (%d); only TRIANGLES (4) is supported",
                                  label.c_str(), mode_name(p.mode), p.mode));
  }
  const auto position = p.attributes.find("POSITION");
  if (position == p.attributes.end()) return fail(file, label + ": has no POSITION attribute");
  AccessorData d;
  SIVIFLOW_TRY(
      view_accessor(file, m, position->second, Usage::kPosition, "POSITION of " + label, &d));
  const std::string position_name =
      text_format("accessor %d (POSITION of %s)", position->second, label.c_str());
  if (d.count > kMaxGltfVertices) {
    return fail(file, text_format("%s: %zu vertices, more than the limit of %zu",
                                  position_name.c_str(), d.count, kMaxGltfVertices));
  }
  SIVIFLOW_TRY(read_vec3s(file, d, position_name, "position", &out->positions));
  const size_t vertex_count = out->positions.size();

  auto read_attribute = [&](const std::string& attribute, Usage usage, bool* present) -> Status {
    *present = false;
    const auto it = p.attributes.find(attribute);
    if (it == p.attributes.end()) return Status::success();
    const std::string what = attribute + " of " + label;
    SIVIFLOW_TRY(view_accessor(file, m, it->second, usage, what, &d));
    if (d.count != vertex_count) {
      return fail(file, text_format("accessor %d (%s): count %zu differs from POSITION's %zu",
                                    it->second, what.c_str(), d.count, vertex_count));
    }
    *present = true;
    const std::string name = text_format("accessor %d (%s)", it->second, what.c_str());
    return usage == Usage::kNormal ? read_vec3s(file, d, name, "normal", &out->normals)
                                   : read_texcoords(file, d, name, &out->texcoords);
  };
  bool present = false;
  if (want_normals) SIVIFLOW_TRY(read_attribute("NORMAL", Usage::kNormal, &present));
  if (texcoord_set >= 0) {
    const std::string attribute = text_format("TEXCOORD_%d", texcoord_set);
    SIVIFLOW_TRY(read_attribute(attribute, Usage::kTexcoord, &present));
    if (!present && texcoords_required) {
      return fail(file, label + ": its base-colour texture uses " + attribute + ", which it lacks");
    }
  }

  if (p.indices >= 0) {
    const std::string what = "indices of " + label;
    SIVIFLOW_TRY(view_accessor(file, m, p.indices, Usage::kIndices, what, &d));
    const std::string name = text_format("accessor %d (%s)", p.indices, what.c_str());
    if (d.count > kMaxGltfIndices) {
      return fail(file, text_format("%s: %zu indices, more than the limit of %zu", name.c_str(),
                                    d.count, kMaxGltfIndices));
    }
    SIVIFLOW_TRY(read_indices(file, d, name, vertex_count, &out->indices));
  } else {
    if (vertex_count % 3 != 0) {
      return fail(file, text_format("%s: not indexed, and its %zu vertices are not a multiple of 3",
                                    label.c_str(), vertex_count));
    }
    out->indices.resize(vertex_count);
    std::iota(out->indices.begin(), out->indices.end(), 0u);
  }
  return Status::success();
}

// --- Nodes ---------------------------------------------------------------------------------------

bool all_finite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

Status local_transform(const std::string& file, const tinygltf::Model& m, int index,
                       glm::dmat4* out) {
  const tinygltf::Node& node = m.nodes[static_cast<size_t>(index)];
  auto bad = [&](const char* field, size_t want, size_t got) {
    return fail(file, text_format("node %d: %s has %zu numbers (expected %zu, all finite)", index,
                                  field, got, want));
  };
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16 || !all_finite(node.matrix))
      return bad("matrix", 16, node.matrix.size());
    glm::dmat4 matrix(1.0);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) matrix[c][r] = node.matrix[static_cast<size_t>(c * 4 + r)];
    }
    *out = matrix;
    return Status::success();
  }
  glm::dvec3 t(0.0);
  glm::dquat r(1.0, 0.0, 0.0, 0.0);
  glm::dvec3 s(1.0);
  if (!node.translation.empty()) {
    if (node.translation.size() != 3 || !all_finite(node.translation)) {
      return bad("translation", 3, node.translation.size());
    }
    t = {node.translation[0], node.translation[1], node.translation[2]};
  }
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4 || !all_finite(node.rotation))
      return bad("rotation", 4, node.rotation.size());
    r = glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1],
                   node.rotation[2]);  // file: x,y,z,w
    const double len = glm::length(r);
    if (!(len > 1e-12))
      return fail(file, text_format("node %d: rotation is a zero quaternion", index));
    r = r / len;
  }
  if (!node.scale.empty()) {
    if (node.scale.size() != 3 || !all_finite(node.scale))
      return bad("scale", 3, node.scale.size());
    s = {node.scale[0], node.scale[1], node.scale[2]};
  }
  const glm::dmat3 rs = glm::mat3_cast(r) * glm::dmat3(glm::dvec3(s.x, 0, 0), glm::dvec3(0, s.y, 0),
                                                       glm::dvec3(0, 0, s.z));
  glm::dmat4 matrix(rs);
  matrix[3] = glm::dvec4(t, 1.0);
  *out = matrix;
  return Status::success();
}

// parent[i] of every node (-1: root). Fails on out-of-range children, a node with two parents
// and cycles.
Status node_parents(const std::string& file, const tinygltf::Model& m, std::vector<int>* parent) {
  const size_t n = m.nodes.size();
  parent->assign(n, -1);
  for (size_t i = 0; i < n; ++i) {
    const tinygltf::Node& node = m.nodes[i];
    if (node.mesh >= 0 && static_cast<size_t>(node.mesh) >= m.meshes.size()) {
      return fail(file, text_format("node %zu: mesh %d does not exist (the file has %zu meshes)", i,
                                    node.mesh, m.meshes.size()));
    }
    for (const int c : node.children) {
      if (c < 0 || static_cast<size_t>(c) >= n) {
        return fail(file, text_format("node %zu: child %d does not exist (the file has %zu nodes)",
                                      i, c, n));
      }
      if ((*parent)[static_cast<size_t>(c)] != -1) {
        return fail(file, text_format("node %d is a child of both node %d and node %zu", c,
                                      (*parent)[static_cast<size_t>(c)], i));
      }
      (*parent)[static_cast<size_t>(c)] = static_cast<int>(i);
    }
  }
  // With one parent each, a cycle is a parent chain that never reaches a root.
  std::vector<uint8_t> state(n, 0);  // 0 unseen, 1 on the current walk, 2 reaches a root
  std::vector<size_t> walk;
  for (size_t i = 0; i < n; ++i) {
    walk.clear();
    size_t at = i;
    while (state[at] == 0) {
      state[at] = 1;
      walk.push_back(at);
      if ((*parent)[at] < 0) break;
      at = static_cast<size_t>((*parent)[at]);
    }
    if (state[at] == 1 && (*parent)[at] >= 0) {
      return fail(file, text_format("node %zu: the node hierarchy has a cycle", at));
    }
    for (const size_t w : walk) state[w] = 2;
  }
  return Status::success();
}

Status global_transform(const std::string& file, const tinygltf::Model& m,
                        const std::vector<int>& parent, int node, glm::dmat4* out) {
  glm::dmat4 world(1.0);
  for (int at = node; at >= 0; at = parent[static_cast<size_t>(at)]) {
    glm::dmat4 local;
    SIVIFLOW_TRY(local_transform(file, m, at, &local));
    world = local * world;
  }
  *out = world;
  return Status::success();
}

glm::vec3 apply(const glm::dmat4& m, const glm::vec3& p) {
  return glm::vec3(m * glm::dvec4(glm::dvec3(p), 1.0));
}

// --- Images --------------------------------------------------------------------------------------

bool is_png(std::span<const uint8_t> b) {
  static constexpr uint8_t kSig[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  return b.size() >= 8 && std::equal(kSig, kSig + 8, b.begin());
}

bool is_jpeg(std::span<const uint8_t> b) {
  return b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
}

uint32_t be16(const uint8_t* p) { return (uint32_t{p[0]} << 8) | p[1]; }
uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

struct Instance {
  int mesh = -1;
  int node = -1;
  glm::dmat4 world{1.0};
};

// Mesh instances of the default scene (see load_gltf_object).
Status collect_instances(const std::string& file, const tinygltf::Model& m,
                         const std::vector<int>& parent, std::vector<Instance>* out) {
  if (m.scenes.empty() && m.nodes.empty()) {
    for (size_t i = 0; i < m.meshes.size(); ++i)
      out->push_back({static_cast<int>(i), -1, glm::dmat4(1.0)});
    return Status::success();
  }
  std::vector<int> roots;
  if (!m.scenes.empty()) {
    if (m.defaultScene >= 0 && static_cast<size_t>(m.defaultScene) >= m.scenes.size()) {
      return fail(file,
                  text_format("scene %d (the default scene) does not exist (the file has %zu)",
                              m.defaultScene, m.scenes.size()));
    }
    const int scene = m.defaultScene >= 0 ? m.defaultScene : 0;
    for (const int r : m.scenes[static_cast<size_t>(scene)].nodes) {
      if (r < 0 || static_cast<size_t>(r) >= m.nodes.size()) {
        return fail(file, text_format("scene %d: node %d does not exist (the file has %zu nodes)",
                                      scene, r, m.nodes.size()));
      }
      roots.push_back(r);
    }
  } else {
    for (size_t i = 0; i < m.nodes.size(); ++i) {
      if (parent[i] < 0) roots.push_back(static_cast<int>(i));
    }
  }
  std::vector<uint8_t> seen(m.nodes.size(), 0);
  std::vector<std::pair<int, glm::dmat4>> stack;  // iterative: hierarchies may be deep
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
    glm::dmat4 above(1.0);
    if (parent[static_cast<size_t>(*it)] >= 0) {
      SIVIFLOW_TRY(global_transform(file, m, parent, parent[static_cast<size_t>(*it)], &above));
    }
    stack.emplace_back(*it, above);
  }
  while (!stack.empty()) {
    const auto [node, above] = stack.back();
    stack.pop_back();
    if (seen[static_cast<size_t>(node)]) {
      return fail(file, text_format("node %d is reached twice from the scene's nodes", node));
    }
    seen[static_cast<size_t>(node)] = 1;
    glm::dmat4 local;
    SIVIFLOW_TRY(local_transform(file, m, node, &local));
    const glm::dmat4 world = above * local;
    const tinygltf::Node& n = m.nodes[static_cast<size_t>(node)];
    if (n.mesh >= 0) out->push_back({n.mesh, node, world});
    for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) stack.emplace_back(*c, world);
  }
  return Status::success();
}

}  // namespace

Status read_regular_file(const std::string& path, size_t max_bytes, std::string* out) {
  return read_file_bytes(path, max_bytes, /*no_follow=*/false, out);
}

Status read_image_extent(std::span<const uint8_t> b, const std::string& what, uint32_t* width,
                         uint32_t* height) {
  if (is_png(b)) {
    // Signature, then the IHDR chunk: length, "IHDR", width, height (big-endian).
    if (b.size() < 24 || std::memcmp(b.data() + 12, "IHDR", 4) != 0) {
      return Status::error(what + ": PNG header truncated or without IHDR");
    }
    *width = be32(b.data() + 16);
    *height = be32(b.data() + 20);
  } else if (is_jpeg(b)) {
    size_t at = 2;
    bool found = false;
    while (!found) {
      const size_t marker_start = at;
      while (at < b.size() && b[at] == 0xFF) ++at;  // 0xFF, then fill bytes, before a marker
      if (at == marker_start || at >= b.size()) {
        return Status::error(what + ": JPEG ends or is corrupt before its frame header");
      }
      const uint8_t marker = b[at++];
      if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) continue;  // no length field
      if (marker == 0xD9 || marker == 0xDA) {
        return Status::error(what + ": JPEG has no frame header before its image data");
      }
      if (b.size() - at < 2) return Status::error(what + ": JPEG segment truncated");
      const size_t length = be16(b.data() + at);
      if (length < 2 || length > b.size() - at)
        return Status::error(what + ": JPEG segment truncated");
      const bool frame =
          marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
      if (frame) {
        if (length < 7) return Status::error(what + ": JPEG frame header truncated");
        *height = be16(b.data() + at + 3);
        *width = be16(b.data() + at + 5);
        found = true;
      }
      at += length;
    }
  } else {
    return Status::error(what + ": not a PNG or JPEG image");
  }
  if (*width == 0 || *height == 0) {
    return Status::error(
        text_format("%s: image extent %ux%u is empty", what.c_str(), *width, *height));
  }
  return Status::success();
}

Status load_river_mesh(const std::string& path, const std::string& mesh_name, TriangleMesh* out) {
  tinygltf::Model model;
  std::vector<std::string> notes;
  SIVIFLOW_TRY(load_model(path, &model, &notes));
  if (model.meshes.empty()) return fail(path, "the file has no meshes");
  int mesh = 0;
  if (!mesh_name.empty()) {
    mesh = -1;
    std::string names;
    for (size_t i = 0; i < model.meshes.size() && mesh < 0; ++i) {
      if (model.meshes[i].name == mesh_name) mesh = static_cast<int>(i);
      if (i < 8) names += (names.empty() ? "'" : ", '") + model.meshes[i].name + "'";
    }
    if (mesh < 0) {
      return fail(path, "has no mesh named '" + mesh_name + "' (its meshes: " + names +
                            (model.meshes.size() > 8 ? ", ...)" : ")"));
    }
  }
  const tinygltf::Mesh& m = model.meshes[static_cast<size_t>(mesh)];
  if (m.primitives.size() != 1) {
    return fail(path,
                text_format("%s has %zu primitives; the river must be exactly one primitive (one "
                            "material), so that its vertex order is defined",
                            mesh_label(model, mesh).c_str(), m.primitives.size()));
  }
  std::vector<int> parent;
  SIVIFLOW_TRY(node_parents(path, model, &parent));
  int node = -1;
  for (size_t i = 0; i < model.nodes.size() && node < 0; ++i) {
    if (model.nodes[i].mesh == mesh) node = static_cast<int>(i);
  }
  glm::dmat4 world(1.0);
  if (node >= 0) SIVIFLOW_TRY(global_transform(path, model, parent, node, &world));

  RawPrimitive raw;
  SIVIFLOW_TRY(read_primitive(path, model, mesh, 0, /*want_normals=*/false, /*texcoord_set=*/-1,
                              false, &raw));
  for (size_t i = 0; i < raw.positions.size(); ++i) {
    raw.positions[i] = apply(world, raw.positions[i]);
    if (!within_world(raw.positions[i])) {
      return fail(path, text_format("%s primitive 0: vertex %zu after the transform of node %d ",
                                    mesh_label(model, mesh).c_str(), i, node) +
                            world_limit_problem(raw.positions[i]));
    }
  }
  TriangleMesh result;
  result.positions = std::move(raw.positions);
  result.indices = std::move(raw.indices);
  result.mesh_name = m.name;
  result.mesh_index = mesh;
  result.node_index = node;
  *out = std::move(result);
  return Status::success();
}

Status hash_gltf_content(const std::string& path, Sha256* content) {
  tinygltf::Model model;
  std::vector<std::string> notes;
  return load_model(path, &model, &notes, content);
}

Status load_gltf_object(const std::string& path, GltfObject* out) {
  tinygltf::Model model;
  std::vector<std::string> notes;
  SIVIFLOW_TRY(load_model(path, &model, &notes));
  std::vector<int> parent;
  SIVIFLOW_TRY(node_parents(path, model, &parent));
  std::vector<Instance> instances;
  SIVIFLOW_TRY(collect_instances(path, model, parent, &instances));

  GltfObject result;
  std::unordered_map<int, int> image_slot;  // glTF image index -> result.images index
  size_t total_vertices = 0;
  size_t total_indices = 0;
  bool have_bounds = false;
  for (const Instance& instance : instances) {
    const tinygltf::Mesh& mesh = model.meshes[static_cast<size_t>(instance.mesh)];
    const glm::dmat3 linear(instance.world);
    const double det = glm::determinant(linear);
    if (!(std::abs(det) > 1e-30)) {  // a zero-scale node hides its mesh
      ++result.skipped_instances;
      continue;
    }
    const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      GltfPrimitive out_prim;
      out_prim.label = text_format("%s primitive %zu (node %d)",
                                   mesh_label(model, instance.mesh).c_str(), pi, instance.node);
      // Material: base-colour factor and texture.
      int texcoord_set = 0;
      bool texcoords_required = false;
      int image = -1;
      if (prim.material >= 0) {
        if (static_cast<size_t>(prim.material) >= model.materials.size()) {
          return fail(path,
                      text_format("%s: material %d does not exist (the file has %zu)",
                                  out_prim.label.c_str(), prim.material, model.materials.size()));
        }
        const tinygltf::PbrMetallicRoughness& pbr =
            model.materials[static_cast<size_t>(prim.material)].pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4 || !all_finite(pbr.baseColorFactor)) {
          return fail(path, text_format("material %d: baseColorFactor must be 4 finite numbers",
                                        prim.material));
        }
        for (int c = 0; c < 4; ++c) {
          out_prim.base_color_factor[c] =
              static_cast<float>(std::clamp(pbr.baseColorFactor[static_cast<size_t>(c)], 0.0, 1.0));
        }
        const tinygltf::TextureInfo& info = pbr.baseColorTexture;
        if (info.index >= 0) {
          if (static_cast<size_t>(info.index) >= model.textures.size()) {
            return fail(
                path,
                text_format("material %d: base-colour texture %d does not exist (the file has %zu)",
                            prim.material, info.index, model.textures.size()));
          }
          image = model.textures[static_cast<size_t>(info.index)].source;
          if (image < 0 || static_cast<size_t>(image) >= model.images.size()) {
            return fail(
                path,
                text_format("texture %d: source image %d does not exist (KTX2, Basis and WebP "
                            "textures are not supported)",
                            info.index, image));
          }
          if (info.texCoord < 0 || info.texCoord > 7) {
            return fail(path, text_format("material %d: base-colour texCoord %d is out of range",
                                          prim.material, info.texCoord));
          }
          texcoord_set = info.texCoord;
          texcoords_required = true;
        }
      }
      RawPrimitive raw;
      SIVIFLOW_TRY(read_primitive(path, model, instance.mesh, static_cast<int>(pi),
                                  /*want_normals=*/true, texcoord_set, texcoords_required, &raw));
      if (raw.positions.size() > kMaxGltfVertices - total_vertices ||
          raw.indices.size() > kMaxGltfIndices - total_indices) {
        return fail(path, text_format("the default scene has more than %zu vertices or %zu indices",
                                      kMaxGltfVertices, kMaxGltfIndices));
      }
      total_vertices += raw.positions.size();
      total_indices += raw.indices.size();

      // Transform, then drop degenerate triangles (they have no normal).
      for (size_t i = 0; i < raw.positions.size(); ++i) {
        raw.positions[i] = apply(instance.world, raw.positions[i]);
        if (!within_world(raw.positions[i])) {
          return fail(path, text_format("%s: vertex %zu after the node transforms ",
                                        out_prim.label.c_str(), i) +
                                world_limit_problem(raw.positions[i]));
        }
      }
      const bool mirrored = det < 0.0;  // a mirroring transform flips the winding
      out_prim.indices.reserve(raw.indices.size());
      std::vector<glm::dvec3> accumulated(raw.normals.empty() ? raw.positions.size() : 0,
                                          glm::dvec3(0.0));
      for (size_t t = 0; t + 2 < raw.indices.size(); t += 3) {
        uint32_t a = raw.indices[t];
        uint32_t b = raw.indices[t + 1];
        uint32_t c = raw.indices[t + 2];
        if (mirrored) std::swap(b, c);
        const glm::dvec3 pa(raw.positions[a]);
        const glm::dvec3 n =
            glm::cross(glm::dvec3(raw.positions[b]) - pa, glm::dvec3(raw.positions[c]) - pa);
        if (a == b || b == c || a == c || glm::dot(n, n) == 0.0) {
          ++result.dropped_triangles;
          continue;
        }
        out_prim.indices.insert(out_prim.indices.end(), {a, b, c});
        if (!accumulated.empty()) {
          accumulated[a] += n;  // |n| = 2 x area: area-weighted
          accumulated[b] += n;
          accumulated[c] += n;
        }
      }
      if (out_prim.indices.empty()) continue;  // nothing drawable in this primitive
      out_prim.normals.resize(raw.positions.size());
      for (size_t i = 0; i < raw.positions.size(); ++i) {
        const glm::dvec3 n =
            raw.normals.empty() ? accumulated[i] : normal_matrix * glm::dvec3(raw.normals[i]);
        const double len = glm::length(n);
        out_prim.normals[i] =
            len > 0.0 && std::isfinite(len) ? glm::vec3(n / len) : glm::vec3(0, 1, 0);
      }
      out_prim.positions = std::move(raw.positions);
      out_prim.texcoords = std::move(raw.texcoords);

      if (image >= 0) {
        const auto found = image_slot.find(image);
        if (found != image_slot.end()) {
          out_prim.base_color_image = found->second;
        } else {
          tinygltf::Image& src = model.images[static_cast<size_t>(image)];
          const std::string what = src.name.empty()
                                       ? text_format("image %d", image)
                                       : text_format("image %d '%s'", image, src.name.c_str());
          if (src.image.empty()) {
            return fail(
                path, with_notes(what + (src.uri.empty() ? ": has no data"
                                                         : ": '" + src.uri + "' could not be read"),
                                 notes));
          }
          GltfImage kept;
          kept.encoded = std::move(src.image);
          kept.source_index = image;
          kept.mime_type = is_png(kept.encoded) ? "image/png" : "image/jpeg";
          SIVIFLOW_TRY(
              read_image_extent(kept.encoded, path + ": " + what, &kept.width, &kept.height));
          if (kept.width > kMaxGltfImageDimension || kept.height > kMaxGltfImageDimension) {
            return fail(path, text_format("%s is %ux%u, larger than the limit of %ux%u",
                                          what.c_str(), kept.width, kept.height,
                                          kMaxGltfImageDimension, kMaxGltfImageDimension));
          }
          out_prim.base_color_image = static_cast<int>(result.images.size());
          image_slot.emplace(image, out_prim.base_color_image);
          result.images.push_back(std::move(kept));
        }
      }

      for (const glm::vec3& p : out_prim.positions) {
        result.bounds_min = have_bounds ? glm::min(result.bounds_min, p) : p;
        result.bounds_max = have_bounds ? glm::max(result.bounds_max, p) : p;
        have_bounds = true;
      }
      result.primitives.push_back(std::move(out_prim));
    }
  }
  if (result.primitives.empty()) {
    return fail(path, model.meshes.empty() ? "the file has no meshes"
                                           : "the default scene has no drawable triangles");
  }
  *out = std::move(result);
  return Status::success();
}

}  // namespace siviflow
