// Scripted input for headless checks of the viewer: mouse and key events at given frames, fed
// through the same handlers as the window's own events (not a real mouse). One event a line:
//   FRAME move X Y          cursor to window pixel (X, Y)
//   FRAME press left|right  button down;  FRAME release left|right  button up
//   FRAME key NAME          a key pressed and released: b (add boulder), x (remove), f (drop a
//                           float), c (camera path), v (debug view), space (pause), escape
//   FRAME wheel N           N notches of the wheel
//   FRAME resize W H        the window resized to W x H (through GLFW)
// Blank lines and lines starting with '#' are skipped.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "siviflow/status.h"

namespace siviflow::view {

struct InputEvent {
  enum class Kind { kMove, kPress, kRelease, kKey, kWheel, kResize };
  uint32_t frame = 0;
  Kind kind = Kind::kMove;
  std::string name;  // button or key
  double x = 0.0;    // pixel, notches or width
  double y = 0.0;    // pixel or height
};

// Reads the script; errors name the file, the line and what is wrong with it.
Status load_input_script(const std::string& path, std::vector<InputEvent>* out);

}  // namespace siviflow::view
