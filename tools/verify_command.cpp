// `siviflow verify DIR [--range A:B]`: checks a folder of captured frames, as a render-farm
// wrangler does before a shot moves on: every frame present, read whole, and captured alike.
#include <cstdio>
#include <string>

#include "cli.h"
#include "commands.h"
#include "siviflow/frame_folder.h"
#include "siviflow/printable_text.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "verify";

void print_help() {
  std::printf(
      "usage: siviflow verify DIR [--range A:B]\n"
      "  Checks the frames DIR/frame_NNNNN.exr of frames A..B-1 (default: from the lowest to the\n"
      "  highest frame in DIR): each must be present, read whole by OpenEXR, hold its own frame\n"
      "  number, and match what made the first good frame: the scene's content (its digest, not\n"
      "  its path), fps, seed, size, AOVs, channels and software version. Frames of the layout\n"
      "  before the digest are another capture. Prints one line per bad frame naming it and the\n"
      "  problem, then a summary; exits 1 if any frame is bad.\n");
}

}  // namespace

int run_verify(int argc, char** argv) {
  std::string dir;
  uint32_t first = 0;
  uint32_t end = 0;
  cli::ArgReader args(argc, argv, 2);
  std::string_view value;
  while (!args.done()) {
    const std::string_view arg = args.next();
    if (arg == "--help" || arg == "-h") {
      print_help();
      return cli::kExitOk;
    } else if (arg == "--range") {
      if (Status s = args.value(arg, &value); !s.ok()) return cli::fail(kCommand, s.message());
      if (Status s = cli::parse_range(arg, value, &first, &end); !s.ok()) {
        return cli::fail(kCommand, s.message());
      }
    } else if (!arg.empty() && arg[0] != '-' && dir.empty()) {
      dir = std::string(arg);
    } else {
      return cli::fail(kCommand, cli::unexpected_argument(arg).message());
    }
  }
  if (dir.empty()) return cli::fail(kCommand, "the folder to check is required (DIR)");

  FrameFolderReport report;
  if (Status s = check_frame_folder(dir, first, end, &report); !s.ok()) {
    return cli::fail(kCommand, s.message());
  }
  for (const FrameProblem& problem : report.problems) {
    std::printf("%s: %s\n", problem.file.c_str(), printable_text(problem.problem).c_str());
  }
  const uint32_t count = report.end - report.first;
  std::printf("%s: frames %u..%u: %u of %u complete%s\n", printable_text(dir).c_str(),
              report.first, report.end - 1, report.complete, count,
              report.problems.empty() ? "" : ", the lines above are not");
  return report.problems.empty() ? cli::kExitOk : cli::kExitError;
}

}  // namespace siviflow
