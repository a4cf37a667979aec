#include "siviflow/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>

namespace siviflow {
namespace {

// Largest single write(); Linux caps one call near 2 GiB anyway.
constexpr size_t kMaxWriteChunk = size_t{1} << 30;
// Attempts at a fresh temporary name before giving up (O_EXCL collisions only).
constexpr int kTempNameAttempts = 64;
// Keeps "<base>.<suffix>" under NAME_MAX (255) for long target names.
constexpr size_t kMaxTempBaseLength = 160;

// Handles both strerror_r flavours: GNU returns the text, XSI fills the buffer.
[[maybe_unused]] const char* strerror_text(char* gnu_result, const char*) { return gnu_result; }
[[maybe_unused]] const char* strerror_text(int xsi_result, const char* buffer) {
  return xsi_result == 0 ? buffer : "unknown error";
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

const char* describe_file_type(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

// Refuses existing non-regular targets: rename() would silently replace a FIFO or device node.
Status check_target(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (S_ISREG(st.st_mode)) return Status::success();
    return Status::error("cannot write " + quoted(path) + ": it exists and is " +
                         describe_file_type(st.st_mode) +
                         ", not a regular file; refusing to replace it");
  }
  const int err = errno;
  if (err == ENOENT) return Status::success();
  return Status::error("cannot write " + quoted(path) + ": " + errno_message(err));
}

Status check_folder(const std::string& path, const std::string& folder) {
  struct stat st {};
  if (::stat(folder.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT) {
      return Status::error("cannot write " + quoted(path) + ": output folder " + quoted(folder) +
                           " does not exist");
    }
    return Status::error("cannot write " + quoted(path) + ": output folder " + quoted(folder) +
                         ": " + errno_message(err));
  }
  if (!S_ISDIR(st.st_mode)) {
    return Status::error("cannot write " + quoted(path) + ": " + quoted(folder) +
                         " is not a folder");
  }
  return Status::success();
}

std::string temp_candidate(const std::string& folder_prefix, const std::string& base) {
  static std::atomic<uint64_t> counter{0};
  struct timespec now {};
  ::clock_gettime(CLOCK_REALTIME, &now);
  char suffix[96];
  std::snprintf(suffix, sizeof suffix, ".tmp-%ld-%llu-%lx", static_cast<long>(::getpid()),
                static_cast<unsigned long long>(counter.fetch_add(1)),
                static_cast<unsigned long>(now.tv_nsec));
  // Leading dot: file browsers and globs such as *.exr skip a half-written temporary.
  return folder_prefix + "." + base.substr(0, kMaxTempBaseLength) + suffix;
}

// Owns the temporary: closes and removes it unless the rename has made it the target.
struct TempFile {
  std::string path;
  int fd = -1;
  bool renamed = false;

  TempFile() = default;
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    if (fd >= 0) ::close(fd);
    if (!renamed && !path.empty()) ::unlink(path.c_str());
  }
};

Status write_all(int fd, const unsigned char* data, size_t size, const std::string& path) {
  while (size > 0) {
    const size_t chunk = size < kMaxWriteChunk ? size : kMaxWriteChunk;
    const ssize_t written = ::write(fd, data, chunk);
    if (written < 0) {
      const int err = errno;
      if (err == EINTR) continue;
      return Status::error("cannot write " + quoted(path) + ": " + errno_message(err));
    }
    if (written == 0) {
      // write() of a non-zero count returning 0 makes no progress; do not spin.
      return Status::error("cannot write " + quoted(path) + ": write made no progress");
    }
    data += written;
    size -= static_cast<size_t>(written);
  }
  return Status::success();
}

// 0 or the errno of the failed fsync.
int fsync_retrying(int fd) {
  while (::fsync(fd) != 0) {
    if (errno != EINTR) return errno;
  }
  return 0;
}

struct PathParts {
  std::string folder;         // "." for a bare file name
  std::string folder_prefix;  // folder with its trailing '/', or empty
  std::string base;
};

Status split_and_check(const std::string& path, PathParts* parts) {
  if (path.empty()) return Status::error("cannot write a file: the path is empty");
  const size_t slash = path.rfind('/');
  parts->folder =
      slash == std::string::npos ? std::string(".") : (slash == 0 ? "/" : path.substr(0, slash));
  parts->folder_prefix = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  parts->base = slash == std::string::npos ? path : path.substr(slash + 1);
  if (parts->base.empty() || parts->base == "." || parts->base == "..") {
    return Status::error("cannot write " + quoted(path) + ": the path names a folder, not a file");
  }
  SIVIFLOW_TRY(check_folder(path, parts->folder));
  return check_target(path);
}

Status write_file_atomically_impl(const std::string& path, const void* data, size_t size) {
  if (data == nullptr && size > 0) {
    return Status::error("cannot write " + quoted(path) + ": no data");
  }
  PathParts parts;
  SIVIFLOW_TRY(split_and_check(path, &parts));
  const std::string& folder = parts.folder;
  const std::string& folder_prefix = parts.folder_prefix;
  const std::string& base = parts.base;

  TempFile temp;
  for (int attempt = 0; attempt < kTempNameAttempts && temp.fd < 0; ++attempt) {
    const std::string candidate = temp_candidate(folder_prefix, base);
    const int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      temp.path = candidate;
      temp.fd = fd;
      break;
    }
    const int err = errno;
    if (err == EINTR || err == EEXIST) continue;
    return Status::error("cannot write " + quoted(path) + ": cannot create a temporary file in " +
                         quoted(folder) + ": " + errno_message(err));
  }
  if (temp.fd < 0) {
    return Status::error("cannot write " + quoted(path) +
                         ": no free temporary file name in " + quoted(folder));
  }

  SIVIFLOW_TRY(write_all(temp.fd, static_cast<const unsigned char*>(data), size, path));
  if (const int err = fsync_retrying(temp.fd); err != 0) {
    return Status::error("cannot write " + quoted(path) + ": fsync failed: " + errno_message(err));
  }
  const int fd = temp.fd;
  temp.fd = -1;  // close() releases the descriptor even when it fails: never close twice
  if (::close(fd) != 0) {
    return Status::error("cannot write " + quoted(path) + ": close failed: " +
                         errno_message(errno));
  }

  // Checked again: the target may have been replaced by a special file while we wrote.
  SIVIFLOW_TRY(check_target(path));
  if (::rename(temp.path.c_str(), path.c_str()) != 0) {
    return Status::error("cannot write " + quoted(path) + ": rename from " + quoted(temp.path) +
                         " failed: " + errno_message(errno));
  }
  temp.renamed = true;

  // Makes the rename itself durable; some filesystems cannot fsync folders (EINVAL): fine.
  const int dir_fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) {
    return Status::error("wrote " + quoted(path) + " but cannot open its folder to sync it: " +
                         errno_message(errno));
  }
  const int sync_err = fsync_retrying(dir_fd);
  ::close(dir_fd);
  if (sync_err != 0 && sync_err != EINVAL) {
    return Status::error("wrote " + quoted(path) + " but syncing its folder failed: " +
                         errno_message(sync_err));
  }
  return Status::success();
}

}  // namespace

std::string errno_message(int error_number) {
  char buffer[256] = {};
  return strerror_text(::strerror_r(error_number, buffer, sizeof buffer), buffer);
}

Status check_output_path(const std::string& path) {
  try {
    PathParts parts;
    return split_and_check(path, &parts);
  } catch (const std::exception&) {
    return Status::error("out of memory");
  }
}

Status write_file_atomically(const std::string& path, const void* data, size_t size) {
  try {
    return write_file_atomically_impl(path, data, size);
  } catch (const std::exception& e) {
    // Building the message may itself run out of memory; "out of memory" fits in SSO.
    try {
      return Status::error("cannot write " + quoted(path) + ": " + e.what());
    } catch (...) {
      return Status::error("out of memory");
    }
  }
}

}  // namespace siviflow
