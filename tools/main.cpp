// siviflow: command-line front end of the SiViFlow library.
#include <malloc.h>

#include <cstdio>
#include <string_view>

#include "cli.h"
#include "commands.h"
#include "siviflow/version.h"

namespace {

void print_usage() {
  std::printf(
      "usage: siviflow <command> [options]\n"
      "commands:\n"
      "  capture   render frames of the default scene into EXR files (and PNG previews)\n"
      "  flow      solve a scene's river flow and write it as CSV\n"
      "  bench     time every pass of the default scene's frames (GPU timestamps) and the CPU work\n"
      "  view      a live window: fly along the river, drag boulders, tune the water\n"
      "  verify    check a folder of captured frames: all present, complete and alike\n"
      "  info      print the Vulkan device, driver, required features and validation layer\n"
      "  version   print the version, as captured frames record it (also --version)\n"
      "Run 'siviflow <command> --help' for the options of a command.\n");
}

// lavapipe's rasterizer mallocs and frees tens of megabytes of bins per frame on its queue
// thread; with glibc's default trim threshold every free hands them back to the kernel
// (madvise) and the next frame faults them in again (about 3300 page faults a frame at 720p).
// This process keeps them: the library itself never changes its host's allocator (docs/
// embedding.md, "On lavapipe: keep freed memory in the process").
constexpr int kKeptFreeBytes = 256 << 20;
// The trim threshold freezes glibc's mmap threshold at 128 KiB; just above OpenEXR's 512 KiB
// Huffman tables, they stay on the heap instead of being mapped afresh for every block.
constexpr int kHeapBlockBytes = 640 << 10;

}  // namespace

int main(int argc, char** argv) {
  mallopt(M_TRIM_THRESHOLD, kKeptFreeBytes);
  mallopt(M_MMAP_THRESHOLD, kHeapBlockBytes);
  if (argc < 2) {
    print_usage();
    return siviflow::cli::kExitError;
  }
  const std::string_view command = argv[1];
  if (command == "--help" || command == "-h" || command == "help") {
    print_usage();
    return siviflow::cli::kExitOk;
  }
  if (command == "--version" || command == "version") {
    if (argc == 3 && (std::string_view(argv[2]) == "--help" || std::string_view(argv[2]) == "-h")) {
      std::printf(
          "usage: siviflow version\n"
          "  Prints the version (also 'siviflow --version'), as captured frames record it in\n"
          "  siviflow/software_version.\n");
      return siviflow::cli::kExitOk;
    }
    if (argc > 2) {
      return siviflow::cli::fail(command, siviflow::cli::unexpected_argument(argv[2]).message());
    }
    std::printf("%s\n", siviflow::version_string());
    return siviflow::cli::kExitOk;
  }
  if (command == "capture") return siviflow::run_capture(argc, argv);
  if (command == "info") return siviflow::run_info(argc, argv);
  if (command == "flow") return siviflow::run_flow(argc, argv);
  if (command == "bench") return siviflow::run_bench(argc, argv);
  if (command == "view") return siviflow::run_view(argc, argv);
  if (command == "verify") return siviflow::run_verify(argc, argv);
  std::fprintf(stderr, "siviflow: unknown command '%.*s' (try 'siviflow --help')\n",
               static_cast<int>(command.size()), command.data());
  return siviflow::cli::kExitError;
}
