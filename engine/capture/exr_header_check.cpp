#include "exr_header_check.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string_view>

#include "siviflow/atomic_file.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// The value sizes of OpenEXR's known fixed-size types: Header::readFrom lets each type read its
// own value and never skips by the size field, so these take this many bytes whatever it says.
struct FixedType {
  std::string_view name;
  int64_t bytes;
};
constexpr FixedType kFixedTypes[] = {
    {"box2i", 16},   {"box2f", 16},     {"chromaticities", 32}, {"compression", 1},
    {"deepImageState", 1}, {"double", 8}, {"envmap", 1},        {"float", 4},
    {"int", 4},      {"keycode", 28},   {"lineOrder", 1},       {"m33f", 36},
    {"m33d", 72},    {"m44f", 64},      {"m44d", 128},          {"rational", 8},
    {"tiledesc", 9}, {"timecode", 8},   {"v2i", 8},             {"v2f", 8},
    {"v2d", 16},     {"v3i", 12},       {"v3f", 12},            {"v3d", 24},
};

class HeaderWalk {
 public:
  HeaderWalk(std::FILE* file, const std::string& what, int64_t file_bytes)
      : file_(file), what_(what), file_bytes_(file_bytes) {}

  Status walk();

 private:
  // A NUL-terminated name of at most 255 characters (OpenEXR's limit).
  bool read_name(std::string* text);
  bool read_int(int64_t* value);
  int64_t left() const { return file_bytes_ - std::ftell(file_); }
  // Steps over `bytes` of the value of attribute `name`, refusing more than the file has left.
  Status skip(const std::string& name, int64_t bytes);
  // Steps over the value of attribute `name` of `type` as OpenEXR reads it.
  Status skip_value(const std::string& name, const std::string& type, int64_t size);

  std::FILE* file_;
  const std::string& what_;
  const int64_t file_bytes_;
};

bool HeaderWalk::read_name(std::string* text) {
  text->clear();
  for (int c = std::fgetc(file_); c != 0; c = std::fgetc(file_)) {
    if (c == EOF || text->size() == 255) return false;
    text->push_back(static_cast<char>(c));
  }
  return true;
}

bool HeaderWalk::read_int(int64_t* value) {
  unsigned char bytes[4];
  if (std::fread(bytes, 1, 4, file_) != 4) return false;
  *value = static_cast<int32_t>(uint32_t{bytes[0]} | uint32_t{bytes[1]} << 8 |
                                uint32_t{bytes[2]} << 16 | uint32_t{bytes[3]} << 24);
  return true;
}

Status HeaderWalk::skip(const std::string& name, int64_t bytes) {
  if (bytes < 0 || bytes > left()) {
    return Status::error(what_ + text_format(": attribute '%s' claims %lld bytes, but the file "
                                             "has %lld left",
                                             name.c_str(), static_cast<long long>(bytes),
                                             static_cast<long long>(left())));
  }
  std::fseek(file_, static_cast<long>(bytes), SEEK_CUR);
  return Status::success();
}

Status HeaderWalk::skip_value(const std::string& name, const std::string& type, int64_t size) {
  if (size < 0) return skip(name, size);
  for (const FixedType& fixed : kFixedTypes) {
    if (fixed.name == type) return skip(name, fixed.bytes);
  }
  const Status ends_inside =
      Status::error(what_ + ": header ends inside attribute '" + name + "'");
  if (type == "chlist") {  // entries (name, 16 bytes) up to an empty name
    std::string channel;
    for (;;) {
      if (!read_name(&channel)) return ends_inside;
      if (channel.empty()) return Status::success();
      SIVIFLOW_TRY(skip(name, 16));
    }
  }
  if (type == "preview") {  // width, height, then RGBA8 pixels
    int64_t width = 0;
    int64_t height = 0;
    if (!read_int(&width) || !read_int(&height)) return ends_inside;
    const uint64_t pixels =
        uint64_t{static_cast<uint32_t>(width)} * static_cast<uint32_t>(height);
    constexpr uint64_t kMostPixels = std::numeric_limits<int64_t>::max() / 4;
    return skip(name, pixels > kMostPixels ? std::numeric_limits<int64_t>::max()
                                           : static_cast<int64_t>(pixels * 4));
  }
  if (type == "stringvector") {  // strings, each after its length, until `size` is read
    for (int64_t read = 0; read < size;) {
      int64_t length = 0;
      if (!read_int(&length)) return ends_inside;
      SIVIFLOW_TRY(skip(name, length));
      read += 4 + length;
    }
    return Status::success();
  }
  return skip(name, size);  // strings, float vectors, ID manifests and unknown types
}

Status HeaderWalk::walk() {
  unsigned char magic_and_version[8];
  if (std::fread(magic_and_version, 1, 8, file_) != 8) {
    return Status::error(what_ + ": too short for an EXR header");
  }
  constexpr unsigned char kMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  if (std::memcmp(magic_and_version, kMagic, 4) != 0) {
    return Status::error(what_ + ": not an EXR file (no EXR magic number)");
  }
  const bool multi_part = (magic_and_version[5] & 0x10) != 0;  // version bit 12
  // An empty name ends a header, and an empty header ends a multi-part file's headers.
  std::string name;
  std::string type;
  for (;;) {
    if (!read_name(&name)) return Status::error(what_ + ": header ends inside an attribute name");
    if (name.empty()) return Status::success();  // no attribute, or after the last header
    for (;;) {
      int64_t size = 0;
      if (!read_name(&type) || !read_int(&size)) {
        return Status::error(what_ + ": header ends inside attribute '" + name + "'");
      }
      SIVIFLOW_TRY(skip_value(name, type, size));
      if (!read_name(&name)) return Status::error(what_ + ": header ends inside an attribute name");
      if (name.empty()) break;
    }
    if (!multi_part) return Status::success();
  }
}

}  // namespace

Status check_exr_headers(const std::string& path, const std::string& what, int64_t file_bytes) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) return Status::error(what + ": " + errno_message(errno));
  return HeaderWalk(file.get(), what, file_bytes).walk();
}

}  // namespace siviflow
