#include "view/input_script.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace siviflow::view {

Status load_input_script(const std::string& path, std::vector<InputEvent>* out) {
  std::ifstream in(path);
  if (!in) return Status::error(path + ": cannot open the input script");
  std::vector<InputEvent> events;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    InputEvent e;
    long long frame = -1;
    std::string kind;
    if (!(words >> frame >> kind) || frame < 0 || frame > UINT32_MAX) {
      return Status::error(where + "expected 'FRAME EVENT ...' with FRAME a frame number");
    }
    e.frame = static_cast<uint32_t>(frame);
    bool ok = true;
    if (kind == "move" || kind == "resize") {
      e.kind = kind == "move" ? InputEvent::Kind::kMove : InputEvent::Kind::kResize;
      ok = static_cast<bool>(words >> e.x >> e.y) && std::isfinite(e.x) && std::isfinite(e.y) &&
           e.x >= 0.0 && e.y >= 0.0 && (kind == "move" || (e.x >= 1.0 && e.y >= 1.0));
    } else if (kind == "press" || kind == "release") {
      e.kind = kind == "press" ? InputEvent::Kind::kPress : InputEvent::Kind::kRelease;
      ok = static_cast<bool>(words >> e.name) && (e.name == "left" || e.name == "right");
    } else if (kind == "key") {
      e.kind = InputEvent::Kind::kKey;
      ok = static_cast<bool>(words >> e.name) &&
           (e.name == "b" || e.name == "x" || e.name == "f" || e.name == "c" || e.name == "v" ||
            e.name == "space" || e.name == "escape");
    } else if (kind == "wheel") {
      e.kind = InputEvent::Kind::kWheel;
      ok = static_cast<bool>(words >> e.x) && std::isfinite(e.x);
    } else {
      return Status::error(where + "unknown event '" + kind +
                           "' (move, press, release, key, wheel, resize)");
    }
    std::string extra;
    if (!ok || (words >> extra)) {
      return Status::error(where + "bad arguments for '" + kind + "': " + line);
    }
    events.push_back(e);
  }
  *out = std::move(events);
  return Status::success();
}

}  // namespace siviflow::view
