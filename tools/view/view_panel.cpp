#include "view/view_panel.h"

#include <imgui.h>

#include "scene/look_fields.h"

namespace siviflow::view {
namespace {

constexpr float kLabelWidth = 150.0f;  // pixels, "reflection_distortion" in the default font

// The slider range of each look field: the renderer's accepted range (water_look.h), or a
// working range where that is unbounded.
struct Range {
  float min;
  float max;
};
Range scalar_range(const char* name) {
  const std::string n = name;
  if (n == "absorption_per_metre" || n == "opacity_per_metre") return {0.0f, 20.0f};
  if (n == "ripple_strength" || n == "foam_amount") return {0.0f, 4.0f};
  if (n == "ripple_scale") return {0.25f, 4.0f};
  if (n == "tile_size_m") return {kMinTileSizeM, kMaxTileSizeM};
  if (n == "reflection_distortion" || n == "refraction_distortion") return {0.0f, 0.5f};
  if (n == "sun_glint") return {0.0f, 10.0f};
  return {0.0f, 1.0f};  // fresnel_f0, reactive_strength
}

void table(const char* title, const std::vector<std::pair<std::string, double>>& rows) {
  if (!ImGui::CollapsingHeader(title, ImGuiTreeNodeFlags_DefaultOpen)) return;
  for (const auto& [name, ms] : rows) ImGui::Text("%-16s %7.2f ms", name.c_str(), ms);
}

}  // namespace

PanelActions draw_panel(const PanelStats& stats, PanelState* state) {
  PanelActions actions;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(330, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("SiViFlow");
  ImGui::Text("%.1f fps  %ux%u  %s", stats.fps, stats.width, stats.height, stats.present_mode);
  ImGui::Text("particles %zu  obstacles %zu", stats.particles, stats.obstacles);
  ImGui::TextWrapped("%s", stats.cursor_water.c_str());
  table("GPU per pass", stats.gpu_ms);
  table("CPU per stage", stats.cpu_ms);

  if (ImGui::CollapsingHeader("Camera and time", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::Checkbox("follow the scene's camera path (C)", &state->follow_path);
    ImGui::Checkbox("pause (space)", &state->paused);
    ImGui::SliderFloat("time scale", &state->time_scale, 0.0f, 4.0f);
    ImGui::Text("t = %.2f s   speed %.1f m/s (wheel)", state->time_seconds, state->camera_speed);
    ImGui::TextWrapped("WASD move, Q/E down/up, right drag look, shift fast; left drag a "
                       "boulder, B adds one under the cursor, X removes it; F drops a float; "
                       "Esc quits.");
  }
  if (ImGui::CollapsingHeader("Water look", ImGuiTreeNodeFlags_DefaultOpen)) {
    WaterLook& look = state->look;
    static constexpr const char* kMaterials[kWaterMaterialCount] = {
        "Tiled Directional Flow", "flow map (two-phase baseline)"};
    for (uint32_t i = 0; i < kWaterMaterialCount; ++i) {
      if (i > 0) ImGui::SameLine();
      if (ImGui::RadioButton(kMaterials[i], look.material == static_cast<WaterMaterial>(i))) {
        look.material = static_cast<WaterMaterial>(i);
        actions.look_changed = true;
      }
    }
    ImGui::PushItemWidth(-kLabelWidth);  // room for the longest field name beside its slider
    for (const LookVectorField& f : kLookVectorFields) {
      glm::vec3& v = look.*f.member;
      const std::string name = f.name;
      if (name == "sun_direction") {
        actions.look_changed |= ImGui::SliderFloat3(f.name, &v.x, -1.0f, 1.0f);
      } else if (name == "sun_color" || name == "opacity_tint") {
        actions.look_changed |= ImGui::SliderFloat3(f.name, &v.x, 0.0f, 4.0f);
      } else {
        actions.look_changed |= ImGui::ColorEdit3(f.name, &v.x, ImGuiColorEditFlags_Float);
      }
    }
    for (const LookScalarField& f : kLookScalarFields) {
      const Range r = scalar_range(f.name);
      actions.look_changed |= ImGui::SliderFloat(f.name, &(look.*f.member), r.min, r.max);
    }
    if (ImGui::Button("defaults")) {
      look = WaterLook{};
      actions.look_changed = true;
    }
    ImGui::InputText("scene file", state->save_path, sizeof(state->save_path));
    ImGui::PopItemWidth();
    actions.save_look = ImGui::Button("save look to scene file");
  }
  if (ImGui::CollapsingHeader("Debug view (V)", ImGuiTreeNodeFlags_DefaultOpen)) {
    static constexpr const char* kLabels[kDebugViewCount] = {
        "the water's look", "flow direction (colour, arrow per tile)", "particles", "tile grid"};
    for (uint32_t i = 0; i < kDebugViewCount; ++i) {
      if (ImGui::RadioButton(kLabels[i], state->debug_view == static_cast<DebugView>(i))) {
        state->debug_view = static_cast<DebugView>(i);
        actions.debug_view_changed = true;
      }
    }
  }
  if (!state->message.empty()) ImGui::TextWrapped("%s", state->message.c_str());
  ImGui::End();
  return actions;
}

}  // namespace siviflow::view
