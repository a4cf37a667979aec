// What a scene is made of, as one digest: frames record it, and a resumed capture or `siviflow
// verify` compares it, so that the same content is the same capture wherever its files lie and
// however their paths are spelled, and an edited file is another capture.
#pragma once

#include <string>

#include "siviflow/scene_file.h"
#include "siviflow/status.h"

namespace siviflow {

// "sha256:" and 64 hex digits over the scene file's text and every byte that loading its rivers
// and objects reads (each glTF file once, with its buffers and images), in the scene's order.
// Null: the built-in default scene, a digest of its name and this build's version (it is code).
// Fails, naming the scene file and the glTF file, where loading a glTF file would.
Status scene_content_digest(const SceneFile* scene, std::string* out);

}  // namespace siviflow
