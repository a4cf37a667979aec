#include "view/fly_camera.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

namespace siviflow::view {
namespace {

constexpr float kTurnRadiansPerPixel = 0.2f * 3.14159265f / 180.0f;
constexpr float kMaxPitch = 1.5f;  // just short of straight up or down, where yaw is undefined
constexpr float kFastFactor = 4.0f;
constexpr float kSpeedStep = 1.25f;
constexpr float kMinSpeed = 0.5f;
constexpr float kMaxSpeed = 200.0f;

}  // namespace

void FlyCamera::look_from(const Camera& camera) {
  position_ = camera.position;
  const glm::vec3 d = glm::normalize(camera.target - camera.position);
  yaw_ = std::atan2(-d.x, -d.z);
  pitch_ = std::asin(std::clamp(d.y, -1.0f, 1.0f));
  fov_y_deg_ = camera.fov_y_deg;
  near_ = camera.near_plane;
  far_ = camera.far_plane;
}

glm::vec3 FlyCamera::forward() const {
  return {-std::sin(yaw_) * std::cos(pitch_), std::sin(pitch_), -std::cos(yaw_) * std::cos(pitch_)};
}

void FlyCamera::turn(glm::vec2 pixels) {
  yaw_ -= pixels.x * kTurnRadiansPerPixel;
  pitch_ = std::clamp(pitch_ - pixels.y * kTurnRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void FlyCamera::move(const MoveInput& input, double seconds) {
  const glm::vec3 f = forward();
  const glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0.0f, 1.0f, 0.0f)));
  const float step = speed_ * (input.fast ? kFastFactor : 1.0f) * static_cast<float>(seconds);
  position_ += step * (input.axes.x * right + input.axes.y * glm::vec3(0.0f, 1.0f, 0.0f) +
                       input.axes.z * f);
}

void FlyCamera::scale_speed(double notches) {
  speed_ = std::clamp(speed_ * std::pow(kSpeedStep, static_cast<float>(notches)), kMinSpeed,
                      kMaxSpeed);
}

Camera FlyCamera::camera() const {
  Camera c;
  c.position = position_;
  c.target = position_ + forward();
  c.fov_y_deg = fov_y_deg_;
  c.near_plane = near_;
  c.far_plane = far_;
  return c;
}

Ray pixel_ray(const View& view, glm::vec2 pixel) {
  const VkExtent2D extent = view.viewport.extent;
  const glm::vec2 ndc(2.0f * (pixel.x + 0.5f) / static_cast<float>(extent.width) - 1.0f,
                      2.0f * (pixel.y + 0.5f) / static_cast<float>(extent.height) - 1.0f);
  const glm::mat4 inverse = glm::inverse(view.projection * view.view);
  const glm::vec4 a = inverse * glm::vec4(ndc, 0.0f, 1.0f);
  const glm::vec4 b = inverse * glm::vec4(ndc, 0.5f, 1.0f);  // finite under infinite far planes
  Ray ray;
  ray.origin = glm::vec3(a) / a.w;
  ray.direction = glm::normalize(glm::vec3(b) / b.w - ray.origin);
  return ray;
}

}  // namespace siviflow::view
