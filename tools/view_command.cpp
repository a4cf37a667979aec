// `siviflow view`: the live viewer (tools/view/viewer.h) from the command line.
#include <cstdio>
#include <string>
#include <string_view>

#include "cli.h"
#include "commands.h"
#include "view/viewer.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "view";

void print_help() {
  std::printf(
      "usage: siviflow view [SCENE.json] [--size WxH] [--frames N] [--no-vsync] [--validation]\n"
      "                     [--screenshot FILE.png] [--input-script FILE] [--flow-report FILE]\n"
      "                     [--debug-view none|flow|particles|tiles]\n"
      "  A window with the scene (or the default scene) and its water, live. Controls: WASD\n"
      "  move, Q/E down/up, hold the right button to look, wheel for speed, shift fast; drag a\n"
      "  boulder with the left button, B adds one under the cursor, X removes the one under it;\n"
      "  F drops a float (a log, then a leaf) under the cursor; C follows the scene's camera\n"
      "  path, space pauses, V steps through the debug views;\n"
      "  Esc or closing the window quits.\n"
      "  --size WxH          window size (default 1280x720)\n"
      "  --frames N          close after N presented frames (time then steps 1/60 s a frame)\n"
      "  --no-vsync          present with MAILBOX or IMMEDIATE where offered (default FIFO)\n"
      "  --validation        the Khronos validation layer with synchronization validation;\n"
      "                      any error makes the exit status 1\n"
      "  --screenshot FILE   with --frames: the last presented image as PNG\n"
      "  --input-script FILE scripted mouse and key events per frame (for checks; see\n"
      "                      tools/view/input_script.h)\n"
      "  --flow-report FILE  at exit, CSV of the obstacles, the floats with their velocity, the\n"
      "                      first river's flow per vertex and its particles with their flow\n"
      "  --debug-view NAME   start with a debug view of the water: flow (direction as colour,\n"
      "                      an arrow per ripple tile), particles (a colour each), tiles (the\n"
      "                      ripple tiles outlined); none is the water's look\n");
}

Status parse_debug_view(std::string_view name, DebugView* view) {
  std::string names;
  for (uint32_t i = 0; i < kDebugViewCount; ++i) {
    const auto candidate = static_cast<DebugView>(i);
    if (name == debug_view_name(candidate)) {
      *view = candidate;
      return Status::success();
    }
    names += std::string(i == 0 ? "" : ", ") + debug_view_name(candidate);
  }
  return Status::error("--debug-view: '" + std::string(name) + "' is not one of " + names);
}

Status parse_options(int argc, char** argv, view::ViewOptions* options, bool* help) {
  cli::ArgReader args(argc, argv, 2);
  std::string_view value;
  while (!args.done()) {
    const std::string_view arg = args.next();
    if (arg == "--help" || arg == "-h") {
      *help = true;
      return Status::success();
    } else if (arg == "--size") {
      SIVIFLOW_TRY(args.value(arg, &value));
      cli::Size size;
      SIVIFLOW_TRY(cli::parse_size(arg, value, &size));
      options->width = size.width;
      options->height = size.height;
    } else if (arg == "--frames") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_uint(arg, value, &options->frames));
      if (options->frames == 0) return Status::error("--frames must be at least 1");
    } else if (arg == "--no-vsync") {
      options->no_vsync = true;
    } else if (arg == "--validation") {
      options->validation = true;
    } else if (arg == "--screenshot") {
      SIVIFLOW_TRY(args.value(arg, &value));
      options->screenshot = value;
    } else if (arg == "--input-script") {
      SIVIFLOW_TRY(args.value(arg, &value));
      options->input_script = value;
    } else if (arg == "--flow-report") {
      SIVIFLOW_TRY(args.value(arg, &value));
      options->flow_report = value;
    } else if (arg == "--debug-view") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(parse_debug_view(value, &options->debug_view));
    } else if (!arg.empty() && arg[0] != '-' && options->scene_path.empty()) {
      options->scene_path = arg;
    } else {
      return cli::unexpected_argument(arg);
    }
  }
  if (!options->screenshot.empty() && options->frames == 0) {
    return Status::error("--screenshot needs --frames N (the image of the last frame)");
  }
  return Status::success();
}

}  // namespace

int run_view(int argc, char** argv) {
  view::ViewOptions options;
  bool help = false;
  const Status parsed = parse_options(argc, argv, &options, &help);
  if (!parsed.ok()) return cli::fail(kCommand, parsed.message());
  if (help) {
    print_help();
    return cli::kExitOk;
  }
  view::ViewResult result;
  const Status status = view::run_viewer(options, &result);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  const double fps = result.seconds > 0.0 ? result.frames_presented / result.seconds : 0.0;
  std::printf("view: %u frames presented in %.2f s (%.1f fps)\n", result.frames_presented,
              result.seconds, fps);
  if (result.validation_errors != 0) {
    return cli::fail(kCommand, std::to_string(result.validation_errors) + " validation error(s)");
  }
  return cli::kExitOk;
}

}  // namespace siviflow
