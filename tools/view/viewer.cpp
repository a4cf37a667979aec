#include "view/viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>

#include "renderer_inspect.h"
#include "siviflow/atomic_file.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_river.h"
#include "siviflow/text_format.h"
#include "siviflow/world.h"
#include "view/float_control.h"
#include "view/fly_camera.h"
#include "view/frame_slots.h"
#include "view/image_barrier.h"
#include "view/input_script.h"
#include "view/look_file.h"
#include "view/obstacle_control.h"
#include "view/screenshot.h"
#include "view/swapchain.h"
#include "view/view_panel.h"
#include "view/window_device.h"

namespace siviflow::view {
namespace {

constexpr uint32_t kFramesInFlight = 2;
constexpr uint64_t kFenceTimeoutNs = 120ull * 1000 * 1000 * 1000;  // lavapipe's JIT can be slow
constexpr double kScriptedFrameSeconds = 1.0 / 60.0;  // scripted runs: the same steps each run
constexpr double kMaxFrameSeconds = 0.1;  // a stall does not fling the camera or the time

const char* present_mode_name(VkPresentModeKHR mode) {
  switch (mode) {
    case VK_PRESENT_MODE_FIFO_KHR: return "FIFO";
    case VK_PRESENT_MODE_MAILBOX_KHR: return "MAILBOX";
    case VK_PRESENT_MODE_IMMEDIATE_KHR: return "IMMEDIATE";
    default: return "other";
  }
}

ImageState state(VkPipelineStageFlags2 stage, VkAccessFlags2 access, VkImageLayout layout) {
  return {stage, access, layout};
}
const ImageState kColorAttachment =
    state(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
const ImageState kDepthWritten =
    state(VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
const ImageState kDepthRead =
    state(VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL);

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

class Viewer {
 public:
  explicit Viewer(const ViewOptions& options) : options_(options) {}
  ~Viewer();
  Status init();
  Status run(ViewResult* result);

 private:
  Status create_water();
  Status init_imgui();
  Status recreate_swapchain();
  Status frame(bool* presented);
  Status record(FrameSlot& slot, uint32_t image_index, const View& view, bool screenshot);
  Status finish_screenshot(uint32_t slot);
  void apply_script_events();
  void step_camera(double seconds);
  void build_panel(uint32_t slot, const std::vector<std::pair<std::string, double>>& cpu_ms);
  Status write_flow_report() const;
  View current_view() const;
  // The first river's water under the cursor, as the panel shows it.
  std::string water_under_cursor() const;

  // Input handlers: the window's callbacks and the input script both call these.
  void on_cursor(double x, double y);
  void on_button(int button, bool pressed);
  void on_key(int key);
  void on_wheel(double notches);
  // Moves the dragged obstacle to the cursor, once for all the cursor events since the last call.
  void apply_drag();
  // Hands the panel's debug view to every river's renderer.
  void apply_debug_view();
  static Viewer* self(GLFWwindow* window) {
    return static_cast<Viewer*>(glfwGetWindowUserPointer(window));
  }

  ViewOptions options_;
  WindowDevice device_;
  Swapchain swapchain_;
  FrameSlots slots_;
  std::unique_ptr<SceneFile> scene_;
  std::vector<SceneRiverData> rivers_;
  std::unique_ptr<World> world_;
  std::vector<std::unique_ptr<Renderer>> renderers_;
  std::vector<Renderer*> renderer_list_;
  ObstacleControl obstacles_;
  FloatControl floats_;
  VkDescriptorPool imgui_pool_ = VK_NULL_HANDLE;
  bool imgui_glfw_ = false;
  bool imgui_vulkan_ = false;
  std::vector<InputEvent> script_;
  Screenshot screenshot_;

  FlyCamera fly_;
  PanelState panel_;
  PanelStats stats_;
  VkExtent2D extent_{0, 0};
  bool recreate_ = false;
  bool quit_ = false;
  uint32_t frame_index_ = 0;  // frames begun (the script's clock)
  uint32_t presented_ = 0;
  double sim_time_ = 0.0;
  glm::vec2 cursor_{0.0f};
  bool looking_ = false;  // right button held over the scene
  bool drag_moved_ = false;  // the cursor moved while dragging since the last frame
  std::chrono::steady_clock::time_point last_frame_;
  // The stages after the panel is built (panel, record, submit and present), shown a frame late.
  std::vector<std::pair<std::string, double>> late_cpu_ms_;
};

Viewer::~Viewer() {
  if (device_.device != VK_NULL_HANDLE) vkDeviceWaitIdle(device_.device);
  if (imgui_vulkan_) ImGui_ImplVulkan_Shutdown();
  if (imgui_glfw_) ImGui_ImplGlfw_Shutdown();
  if (ImGui::GetCurrentContext() != nullptr) ImGui::DestroyContext();
  if (imgui_pool_ != VK_NULL_HANDLE) vkDestroyDescriptorPool(device_.device, imgui_pool_, nullptr);
  screenshot_.destroy();
  renderers_.clear();
  world_.reset();
  slots_.destroy();
  swapchain_.destroy();
}

Status Viewer::init() {
  if (!options_.input_script.empty()) {
    SIVIFLOW_TRY(load_input_script(options_.input_script, &script_));
  }
  if (!options_.scene_path.empty()) {
    scene_ = std::make_unique<SceneFile>();
    SIVIFLOW_TRY(load_scene_file(options_.scene_path, scene_.get()));
  }
  WindowDeviceOptions window;
  window.width = options_.width;
  window.height = options_.height;
  window.validation = options_.validation;
  SIVIFLOW_TRY(device_.create(window));
  glfwSetWindowUserPointer(device_.window, this);
  glfwSetCursorPosCallback(device_.window, [](GLFWwindow* w, double x, double y) {
    self(w)->on_cursor(x, y);
  });
  glfwSetMouseButtonCallback(device_.window, [](GLFWwindow* w, int button, int action, int) {
    self(w)->on_button(button, action == GLFW_PRESS);
  });
  glfwSetKeyCallback(device_.window, [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_PRESS) self(w)->on_key(key);
  });
  glfwSetScrollCallback(device_.window, [](GLFWwindow* w, double, double y) {
    self(w)->on_wheel(y);
  });
  SIVIFLOW_TRY(swapchain_.init(device_, options_.no_vsync));
  bool minimised = false;
  SIVIFLOW_TRY(swapchain_.recreate(&minimised));
  if (minimised) return Status::error("the window opened with no area");
  extent_ = swapchain_.extent();
  SIVIFLOW_TRY(slots_.create(device_, kFramesInFlight, extent_));
  SIVIFLOW_TRY(create_water());
  SIVIFLOW_TRY(init_imgui());
  fly_.look_from(world_->scene_camera(0.0));
  std::snprintf(panel_.save_path, sizeof(panel_.save_path), "%s",
                options_.scene_path.empty() ? "look.json" : options_.scene_path.c_str());
  panel_.look = renderers_.front()->look();
  panel_.debug_view = options_.debug_view;
  apply_debug_view();
  last_frame_ = std::chrono::steady_clock::now();
  return Status::success();
}

Status Viewer::create_water() {
  WorldCreateInfo world_info;
  world_info.instance = device_.instance;
  world_info.physical_device = device_.physical_device;
  world_info.device = device_.device;
  world_info.get_instance_proc_addr = vkGetInstanceProcAddr;
  world_info.get_device_proc_addr = vkGetDeviceProcAddr;
  world_info.frames_in_flight = kFramesInFlight;
  world_info.color_format = kFrameColorFormat;
  world_info.depth_format = kFrameDepthFormat;
  world_info.scene = scene_.get();
  world_info.debug_utils = device_.validation;
  world_info.spare_boulders = kSpareBoulders;
  world_info.spare_boulder_radius = kSpareBoulderRadius;
  world_info.spare_logs = kSpareLogs;
  world_info.spare_leaves = kSpareLeaves;
  SIVIFLOW_TRY(World::create(world_info, &world_));
  const size_t scene_obstacles = world_->boulder_count() - kSpareBoulders;

  const size_t river_count = scene_ != nullptr ? scene_->rivers.size() : 1;
  rivers_.resize(river_count);
  for (size_t i = 0; i < river_count; ++i) {
    SIVIFLOW_TRY(scene_river_data(scene_.get(), i, &rivers_[i]));
    // The scene's obstacles go in as runtime obstacles (ObstacleControl), so they can move;
    // the objects' footprints stay with the river.
    WaterRiver river = rivers_[i].river();
    river.obstacles = river.obstacles.subspan(scene_obstacles);
    CreateInfo info = device_.renderer_create_info(extent_);
    info.frames_in_flight = kFramesInFlight;
    info.color_format = kFrameColorFormat;
    info.depth_format = kFrameDepthFormat;
    info.seed = scene_ != nullptr ? scene_->render.seed : 1;
    info.river = &river;
    info.look = scene_ != nullptr ? &scene_->look : nullptr;
    info.enable_timing = true;
    info.reflection = &World::draw_reflection;
    info.reflection_user = world_.get();
    std::unique_ptr<Renderer> renderer;
    SIVIFLOW_TRY(Renderer::create(info, &renderer));
    SIVIFLOW_TRY(renderer->set_occluders(world_->occluders()));
    renderer_list_.push_back(renderer.get());
    renderers_.push_back(std::move(renderer));
  }
  SIVIFLOW_TRY(obstacles_.init(rivers_, scene_obstacles, renderer_list_, world_.get()));
  return floats_.init(scene_.get(), renderer_list_, world_.get());
}

Status Viewer::init_imgui() {
  const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 8}};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  pool_info.maxSets = 8;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = sizes;
  VkResult result = vkCreateDescriptorPool(device_.device, &pool_info, nullptr, &imgui_pool_);
  if (result != VK_SUCCESS) return vk_failure("vkCreateDescriptorPool", result);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the working folder
  ImGui::StyleColorsDark();
  // After our callbacks: the backend chains to them.
  imgui_glfw_ = ImGui_ImplGlfw_InitForVulkan(device_.window, true);
  if (!imgui_glfw_) return Status::error("Dear ImGui's GLFW backend did not start");
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = device_.instance;
  info.PhysicalDevice = device_.physical_device;
  info.Device = device_.device;
  info.QueueFamily = device_.queue_family;
  info.Queue = device_.queue;
  info.DescriptorPool = imgui_pool_;
  info.Subpass = 0;
  info.MinImageCount = swapchain_.min_image_count();
  // Its vertex buffers rotate per call: at least one per frame in flight.
  info.ImageCount = std::max(swapchain_.image_count(), kFramesInFlight);
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  imgui_vulkan_ = ImGui_ImplVulkan_Init(&info, swapchain_.overlay_pass());
  if (!imgui_vulkan_) return Status::error("Dear ImGui's Vulkan backend did not start");

  // The font atlas, uploaded once before the first frame.
  FrameSlot& slot = slots_[0];
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(slot.cmd, &begin);
  ImGui_ImplVulkan_CreateFontsTexture(slot.cmd);
  vkEndCommandBuffer(slot.cmd);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &slot.cmd;
  result = vkQueueSubmit(device_.queue, 1, &submit, VK_NULL_HANDLE);
  if (result != VK_SUCCESS) return vk_failure("vkQueueSubmit", result);
  result = vkQueueWaitIdle(device_.queue);
  if (result != VK_SUCCESS) return vk_failure("vkQueueWaitIdle", result);
  ImGui_ImplVulkan_DestroyFontUploadObjects();
  return Status::success();
}

// A new swapchain at the window's size, and the frame images and the water with it.
Status Viewer::recreate_swapchain() {
  VkResult result = vkDeviceWaitIdle(device_.device);
  if (result != VK_SUCCESS) return vk_failure("vkDeviceWaitIdle", result);
  bool minimised = false;
  SIVIFLOW_TRY(swapchain_.recreate(&minimised));
  if (minimised) return Status::success();  // tried again once the window has an area
  recreate_ = false;
  if (swapchain_.extent().width == extent_.width && swapchain_.extent().height == extent_.height) {
    return Status::success();
  }
  extent_ = swapchain_.extent();
  SIVIFLOW_TRY(slots_.resize(extent_));
  for (Renderer* renderer : renderer_list_) SIVIFLOW_TRY(renderer->resize(extent_));
  return Status::success();
}

void Viewer::on_cursor(double x, double y) {
  const glm::vec2 now(static_cast<float>(x), static_cast<float>(y));
  if (looking_) fly_.turn(now - cursor_);
  cursor_ = now;
  drag_moved_ = obstacles_.dragging();  // re-solved once per frame, however many events came
}

void Viewer::apply_debug_view() {
  for (Renderer* renderer : renderer_list_) {
    const Status status = renderer->set_debug_view(panel_.debug_view);
    if (!status.ok()) panel_.message = status.message();
  }
}

void Viewer::apply_drag() {
  if (!drag_moved_) return;
  drag_moved_ = false;
  const Status status = obstacles_.drag_to(pixel_ray(current_view(), cursor_));
  if (!status.ok()) panel_.message = status.message();
}

void Viewer::on_button(int button, bool pressed) {
  const bool over_panel = ImGui::GetCurrentContext() != nullptr && ImGui::GetIO().WantCaptureMouse;
  if (button == GLFW_MOUSE_BUTTON_RIGHT) looking_ = pressed && !over_panel;
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  if (!pressed) {
    apply_drag();  // where the button came up
    obstacles_.end_drag();
  } else if (!over_panel) {
    obstacles_.begin_drag(pixel_ray(current_view(), cursor_), sim_time_);
  }
}

void Viewer::on_key(int key) {
  if (ImGui::GetCurrentContext() != nullptr && ImGui::GetIO().WantCaptureKeyboard) return;
  const Ray ray = pixel_ray(current_view(), cursor_);
  Status status;
  switch (key) {
    case GLFW_KEY_ESCAPE: quit_ = true; break;
    case GLFW_KEY_C: panel_.follow_path = !panel_.follow_path; break;
    case GLFW_KEY_SPACE: panel_.paused = !panel_.paused; break;
    case GLFW_KEY_V:
      panel_.debug_view =
          static_cast<DebugView>((static_cast<uint32_t>(panel_.debug_view) + 1) % kDebugViewCount);
      apply_debug_view();
      break;
    case GLFW_KEY_B: status = obstacles_.add_at(ray); break;
    case GLFW_KEY_F: {
      const std::optional<glm::vec3> hit = obstacles_.hit_water(ray);
      status = hit ? floats_.drop_at(*hit) : Status::error("no water under the cursor to drop a float on");
      break;
    }
    case GLFW_KEY_X: {
      bool removed = false;
      status = obstacles_.remove_at(ray, sim_time_, &removed);
      if (status.ok() && !removed) panel_.message = "no boulder under the cursor";
      break;
    }
    default: break;
  }
  if (!status.ok()) panel_.message = status.message();
}

void Viewer::on_wheel(double notches) {
  if (ImGui::GetCurrentContext() != nullptr && ImGui::GetIO().WantCaptureMouse) return;
  fly_.scale_speed(notches);
}

void Viewer::apply_script_events() {
  static const struct {
    const char* name;
    int key;
  } kKeys[] = {{"b", GLFW_KEY_B}, {"x", GLFW_KEY_X}, {"f", GLFW_KEY_F}, {"c", GLFW_KEY_C}, {"v", GLFW_KEY_V},
               {"space", GLFW_KEY_SPACE}, {"escape", GLFW_KEY_ESCAPE}};
  for (const InputEvent& e : script_) {
    if (e.frame != frame_index_) continue;
    switch (e.kind) {
      case InputEvent::Kind::kMove: on_cursor(e.x, e.y); break;
      case InputEvent::Kind::kPress:
      case InputEvent::Kind::kRelease:
        on_button(e.name == "left" ? GLFW_MOUSE_BUTTON_LEFT : GLFW_MOUSE_BUTTON_RIGHT,
                  e.kind == InputEvent::Kind::kPress);
        break;
      case InputEvent::Kind::kKey:
        for (const auto& k : kKeys) {
          if (e.name == k.name) on_key(k.key);
        }
        break;
      case InputEvent::Kind::kWheel: on_wheel(e.x); break;
      case InputEvent::Kind::kResize:
        glfwSetWindowSize(device_.window, static_cast<int>(e.x), static_cast<int>(e.y));
        recreate_ = true;
        break;
    }
  }
}

std::string Viewer::water_under_cursor() const {
  const std::optional<glm::vec3> hit = obstacles_.hit_water(pixel_ray(current_view(), cursor_));
  if (!hit) return "cursor: not over the water";
  for (const Renderer* renderer : renderer_list_) {
    WaterSample s;
    if (!renderer->query_water({&*hit, 1}, {&s, 1}).ok() || !s.on_surface) continue;
    if (!s.wet) return text_format("cursor: in an obstacle's footprint (id %u)", s.obstacle);
    return text_format("cursor: water at y %.2f m, flow %.2f m/s (x %.2f, z %.2f), depth %.2f m, "
                       "foam %.2f",
                       double(s.surface.y), double(glm::length(s.velocity)), double(s.velocity.x),
                       double(s.velocity.z), double(s.depth), double(s.foam));
  }
  return "cursor: not over the water";
}

View Viewer::current_view() const {
  const Camera camera = panel_.follow_path ? world_->scene_camera(sim_time_) : fly_.camera();
  return camera_view(camera, extent_);
}

void Viewer::step_camera(double seconds) {
  if (panel_.follow_path) return;
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  GLFWwindow* w = device_.window;
  const auto held = [w](int key) { return glfwGetKey(w, key) == GLFW_PRESS ? 1.0f : 0.0f; };
  MoveInput input;
  input.axes = {held(GLFW_KEY_D) - held(GLFW_KEY_A), held(GLFW_KEY_E) - held(GLFW_KEY_Q),
                held(GLFW_KEY_W) - held(GLFW_KEY_S)};
  input.fast = held(GLFW_KEY_LEFT_SHIFT) > 0.0f;
  fly_.move(input, seconds);
}

Status Viewer::run(ViewResult* result) {
  const auto start = std::chrono::steady_clock::now();
  while (!quit_ && glfwWindowShouldClose(device_.window) == GLFW_FALSE) {
    if (options_.frames != 0 && presented_ >= options_.frames) break;
    bool presented = false;
    SIVIFLOW_TRY(frame(&presented));
    if (presented) ++presented_;
  }
  result->frames_presented = presented_;
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  VkResult waited = vkDeviceWaitIdle(device_.device);
  if (waited != VK_SUCCESS) return vk_failure("vkDeviceWaitIdle", waited);
  result->validation_errors = device_.validation_error_count();
  if (!options_.flow_report.empty()) SIVIFLOW_TRY(write_flow_report());
  return Status::success();
}

Status Viewer::frame(bool* presented) {
  const auto events_start = std::chrono::steady_clock::now();
  glfwPollEvents();
  apply_script_events();
  apply_drag();
  int width = 0;
  int height = 0;
  glfwGetFramebufferSize(device_.window, &width, &height);
  if (width == 0 || height == 0) {  // minimised: nothing to present until it comes back
    glfwWaitEventsTimeout(0.1);
    return Status::success();
  }
  if (recreate_ || static_cast<uint32_t>(width) != extent_.width ||
      static_cast<uint32_t>(height) != extent_.height) {
    SIVIFLOW_TRY(recreate_swapchain());
    if (recreate_) return Status::success();
  }
  const double events_ms = ms_since(events_start);

  const uint32_t slot_index = frame_index_ % kFramesInFlight;
  FrameSlot& slot = slots_[slot_index];
  const auto wait_start = std::chrono::steady_clock::now();
  VkResult result = vkWaitForFences(device_.device, 1, &slot.fence, VK_TRUE, kFenceTimeoutNs);
  if (result != VK_SUCCESS) return vk_failure("vkWaitForFences", result);
  const double wait_ms = ms_since(wait_start);
  slots_.read_timestamps(slot_index);

  uint32_t image_index = 0;
  result = vkAcquireNextImageKHR(device_.device, swapchain_.swapchain(), kFenceTimeoutNs,
                                 slot.acquired, VK_NULL_HANDLE, &image_index);
  if (result == VK_ERROR_OUT_OF_DATE_KHR) {
    recreate_ = true;
    return Status::success();
  }
  if (result == VK_SUBOPTIMAL_KHR) {
    recreate_ = true;  // this image still presents; a new swapchain after it
  } else if (result != VK_SUCCESS) {
    return vk_failure("vkAcquireNextImageKHR", result);
  }

  const auto now = std::chrono::steady_clock::now();
  double seconds = std::min(std::chrono::duration<double>(now - last_frame_).count(), kMaxFrameSeconds);
  last_frame_ = now;
  stats_.fps = seconds > 0.0 ? 1.0 / seconds : 0.0;
  if (!script_.empty() || options_.frames != 0) seconds = kScriptedFrameSeconds;
  step_camera(seconds);
  if (!panel_.paused) sim_time_ += seconds * panel_.time_scale;

  const auto update_start = std::chrono::steady_clock::now();
  const View view = current_view();
  SIVIFLOW_TRY(world_->begin_frame(slot_index));
  for (Renderer* renderer : renderer_list_) {
    SIVIFLOW_TRY(renderer->begin_frame(slot_index));
    SIVIFLOW_TRY(renderer->update(view, sim_time_));
  }
  SIVIFLOW_TRY(floats_.step(sim_time_));
  const double update_ms = ms_since(update_start);

  const auto panel_start = std::chrono::steady_clock::now();
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  build_panel(slot_index, {{"events", events_ms}, {"fence wait", wait_ms}, {"update", update_ms}});
  ImGui::Render();
  const double panel_ms = ms_since(panel_start);

  const bool screenshot = !options_.screenshot.empty() && options_.frames != 0 &&
                          presented_ + 1 == options_.frames;
  const auto record_start = std::chrono::steady_clock::now();
  SIVIFLOW_TRY(record(slot, image_index, view, screenshot));
  late_cpu_ms_ = {{"panel", panel_ms}, {"record", ms_since(record_start)}};

  const auto submit_start = std::chrono::steady_clock::now();
  result = vkResetFences(device_.device, 1, &slot.fence);
  if (result != VK_SUCCESS) return vk_failure("vkResetFences", result);
  VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  wait.semaphore = slot.acquired;
  wait.stageMask = VK_PIPELINE_STAGE_2_BLIT_BIT;  // the first use of the swapchain image
  VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  signal.semaphore = swapchain_.present_semaphore(image_index);
  signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  VkCommandBufferSubmitInfo command{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  command.commandBuffer = slot.cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.waitSemaphoreInfoCount = 1;
  submit.pWaitSemaphoreInfos = &wait;
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &command;
  submit.signalSemaphoreInfoCount = 1;
  submit.pSignalSemaphoreInfos = &signal;
  result = vkQueueSubmit2(device_.queue, 1, &submit, slot.fence);
  if (result != VK_SUCCESS) return vk_failure("vkQueueSubmit2", result);

  VkSwapchainKHR swapchain = swapchain_.swapchain();
  const VkSemaphore rendered = swapchain_.present_semaphore(image_index);
  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &rendered;
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain;
  present.pImageIndices = &image_index;
  result = vkQueuePresentKHR(device_.queue, &present);
  if (result == VK_ERROR_OUT_OF_DATE_KHR || result == VK_SUBOPTIMAL_KHR) {
    recreate_ = true;
  } else if (result != VK_SUCCESS) {
    return vk_failure("vkQueuePresentKHR", result);
  }
  slot.timestamps_written = true;
  late_cpu_ms_.push_back({"submit+present", ms_since(submit_start)});
  ++frame_index_;
  *presented = true;
  if (screenshot) SIVIFLOW_TRY(finish_screenshot(slot_index));
  return Status::success();
}

void Viewer::build_panel(uint32_t slot, const std::vector<std::pair<std::string, double>>& cpu_ms) {
  stats_.cpu_ms = cpu_ms;
  stats_.cpu_ms.insert(stats_.cpu_ms.end(), late_cpu_ms_.begin(), late_cpu_ms_.end());
  stats_.gpu_ms.clear();
  if (slots_[slot].timestamps_written) {
    stats_.gpu_ms.push_back({"world", slots_.gpu_ms(slot, kFrameStart, kAfterWorld)});
    std::vector<PassTime> times;
    for (size_t r = 0; r < renderer_list_.size(); ++r) {
      if (!renderer_list_[r]->pass_times(slot, &times).ok()) continue;
      for (const PassTime& pass : times) {
        const std::string prefix = renderer_list_.size() > 1 ? "river " + std::to_string(r) + " " : "";
        stats_.gpu_ms.push_back({"  " + prefix + pass.name, pass.milliseconds});
      }
    }
    stats_.gpu_ms.push_back({"water", slots_.gpu_ms(slot, kAfterWorld, kAfterWater)});
    stats_.gpu_ms.push_back({"copy+panel", slots_.gpu_ms(slot, kAfterWater, kAfterOverlay)});
    stats_.gpu_ms.push_back({"frame", slots_.gpu_ms(slot, kFrameStart, kAfterOverlay)});
  }
  stats_.particles = 0;
  for (Renderer* renderer : renderer_list_) {
    stats_.particles += particle_field(*renderer).particles().size();
  }
  stats_.obstacles = obstacles_.placed(sim_time_).size();
  stats_.cursor_water = water_under_cursor();
  stats_.present_mode = present_mode_name(swapchain_.present_mode());
  stats_.width = extent_.width;
  stats_.height = extent_.height;
  panel_.time_seconds = sim_time_;
  panel_.camera_speed = fly_.speed();
  const PanelActions actions = draw_panel(stats_, &panel_);
  if (actions.look_changed) {
    for (Renderer* renderer : renderer_list_) {
      const Status status = renderer->set_look(panel_.look);
      panel_.message = status.ok() ? "" : status.message();
    }
  }
  if (actions.debug_view_changed) apply_debug_view();
  if (actions.save_look) {
    const Status status = save_look_to_scene(panel_.save_path, renderers_.front()->look());
    panel_.message = status.ok() ? std::string("look saved to ") + panel_.save_path
                                 : status.message();
  }
}

Status Viewer::record(FrameSlot& slot, uint32_t image_index, const View& view, bool screenshot) {
  VkCommandBuffer cmd = slot.cmd;
  VkResult result = vkResetCommandPool(device_.device, slot.pool, 0);
  if (result != VK_SUCCESS) return vk_failure("vkResetCommandPool", result);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  result = vkBeginCommandBuffer(cmd, &begin);
  if (result != VK_SUCCESS) return vk_failure("vkBeginCommandBuffer", result);
  vkCmdResetQueryPool(cmd, slot.timestamps, 0, kTimestampCount);
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.timestamps, kFrameStart);

  // The world into the frame's colour and depth, left as attachments for the water.
  ExternalImage color = slot.color;
  ExternalImage depth = slot.depth;
  color.final = kColorAttachment;
  depth.final = kDepthWritten;
  SIVIFLOW_TRY(world_->record(cmd, view, sim_time_, color, depth));
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.timestamps, kAfterWorld);

  // Each river's water over it; the last leaves the colour ready to be copied out.
  ImageState color_now = kColorAttachment;
  ImageState depth_now = kDepthWritten;
  for (size_t i = 0; i < renderer_list_.size(); ++i) {
    const bool last = i + 1 == renderer_list_.size();
    FrameInputs inputs;
    inputs.color = slot.color;
    inputs.depth = slot.depth;
    inputs.color.current = color_now;
    inputs.depth.current = depth_now;
    if (!last) {
      inputs.color.final = kColorAttachment;
      inputs.depth.final = kDepthRead;
    }
    SIVIFLOW_TRY(renderer_list_[i]->record(cmd, inputs));
    color_now = inputs.color.final;
    depth_now = inputs.depth.final;
  }
  slot.color.current = color_now;
  slot.depth.current = depth_now;
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.timestamps, kAfterWater);

  // The frame into the swapchain image (the blit encodes sRGB), then the panel over it.
  const VkImage target = swapchain_.image(image_index);
  const ImageState acquired = state(VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_NONE,
                                    VK_IMAGE_LAYOUT_UNDEFINED);
  const ImageState blit_dst = state(VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  const ImageState overlay =
      state(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  image_barrier(cmd, target, acquired, blit_dst);
  VkImageBlit region{};
  region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.srcOffsets[1] = {static_cast<int32_t>(extent_.width), static_cast<int32_t>(extent_.height), 1};
  region.dstOffsets[1] = region.srcOffsets[1];
  vkCmdBlitImage(cmd, slot.color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region, VK_FILTER_NEAREST);
  image_barrier(cmd, target, blit_dst, overlay);

  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  pass.renderPass = swapchain_.overlay_pass();
  pass.framebuffer = swapchain_.framebuffer(image_index);
  pass.renderArea = {{0, 0}, extent_};
  vkCmdBeginRenderPass(cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
  vkCmdEndRenderPass(cmd);

  // A layout transition runs in no stage: only the barrier's second scope chains it into the
  // semaphore's signal (ALL_COMMANDS), which the present waits on.
  const ImageState present = state(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_NONE,
                                   VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
  if (screenshot) {
    SIVIFLOW_TRY(screenshot_.record_copy(device_, cmd, target, overlay, extent_));
    image_barrier(cmd, target, Screenshot::kCopySource, present);
  } else {
    image_barrier(cmd, target, overlay, present);
  }
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, slot.timestamps, kAfterOverlay);
  result = vkEndCommandBuffer(cmd);
  if (result != VK_SUCCESS) return vk_failure("vkEndCommandBuffer", result);
  return Status::success();
}

Status Viewer::finish_screenshot(uint32_t slot) {
  VkResult result = vkWaitForFences(device_.device, 1, &slots_[slot].fence, VK_TRUE, kFenceTimeoutNs);
  if (result != VK_SUCCESS) return vk_failure("vkWaitForFences", result);
  return screenshot_.write_png(options_.screenshot, swapchain_.format());
}

// For scripted checks: where the obstacles stand, the river's flow per vertex (what the next
// frame's particles read) and the flow each particle of this frame carries.
Status Viewer::write_flow_report() const {
  std::string csv = "kind,x,y,z,a,b,c\n";
  char row[256];
  for (const ObstacleControl::Placed& p : obstacles_.placed(sim_time_)) {
    std::snprintf(row, sizeof(row), "obstacle,%.6g,%.6g,%.6g,%.6g,0,0\n", p.centre.x, p.centre.y,
                  p.centre.z, p.radius);
    csv += row;
  }
  for (const FloatPose& f : floats_.poses()) {
    if (!f.shown) continue;
    std::snprintf(row, sizeof(row), "float,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", f.centre.x, f.centre.y,
                  f.centre.z, f.velocity.x, f.velocity.y, f.velocity.z);
    csv += row;
  }
  const RiverFlowField& field = flow_field(*renderer_list_.front());
  for (size_t v = 0; v < field.positions.size(); ++v) {
    const glm::vec3& p = field.positions[v];
    std::snprintf(row, sizeof(row), "vertex,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", p.x, p.y, p.z,
                  field.flow[v].x, field.flow[v].y, field.flow[v].z);
    csv += row;
  }
  for (const Particle& particle : particle_field(*renderer_list_.front()).particles()) {
    std::snprintf(row, sizeof(row), "particle,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", particle.world.x,
                  particle.world.y, particle.world.z, particle.flow.x, particle.flow.y,
                  particle.flow.z);
    csv += row;
  }
  return write_file_atomically(options_.flow_report, csv.data(), csv.size());
}

}  // namespace

Status run_viewer(const ViewOptions& options, ViewResult* result) {
  Viewer viewer(options);
  SIVIFLOW_TRY(viewer.init());
  return viewer.run(result);
}

}  // namespace siviflow::view
