#include "view/look_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene/look_fields.h"
#include "siviflow/atomic_file.h"
#include "siviflow/scene_file.h"

namespace siviflow::view {

Status save_look_to_scene(const std::string& path, const WaterLook& look) {
  using Json = nlohmann::json;
  // A new file: the procedural river holding the look (a scene needs a river).
  Json root = {{"version", kSceneFileVersion}, {"river", {{"procedural", Json::object()}}}};
  std::error_code error;
  if (std::filesystem::exists(path, error)) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    if (!in) return Status::error(path + ": cannot read it");
    root = Json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
    if (!root.is_object()) {
      return Status::error(path + ": not a scene file (not a JSON object); the look was not saved");
    }
  }
  Json fields = {{"material", water_material_name(look.material)}};
  for (const LookScalarField& f : kLookScalarFields) fields[f.name] = look.*f.member;
  for (const LookVectorField& f : kLookVectorFields) {
    const glm::vec3& v = look.*f.member;
    fields[f.name] = {v.x, v.y, v.z};
  }
  root["look"] = fields;
  const std::string bytes = root.dump(2) + "\n";
  // What we write must be a scene file we read back: refuse to replace a file with one that
  // the parser would not take (the look's ranges are the renderer's, already checked).
  SceneFile check;
  const std::string folder = std::filesystem::path(path).parent_path().string();
  SIVIFLOW_TRY(parse_scene_file(bytes, path, folder.empty() ? "." : folder, &check));
  return write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace siviflow::view
