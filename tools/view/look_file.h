// "Save look to scene file": the panel's look written back as a scene file's "look" object.
#pragma once

#include <string>

#include "siviflow/status.h"
#include "siviflow/water_look.h"

namespace siviflow::view {

// Writes every field of `look` into the "look" object of the scene file at `path`, keeping its
// other keys; a missing file becomes a scene file of the procedural river with the look. The file is replaced
// atomically; a file that is not a JSON object is refused and left as it was.
Status save_look_to_scene(const std::string& path, const WaterLook& look);

}  // namespace siviflow::view
