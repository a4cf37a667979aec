// The viewer's fly camera: WASD to move, mouse look while the right button is held, the wheel
// changes speed; or the scene's own camera path. Turns a window pixel into a world ray.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "siviflow/renderer.h"

namespace siviflow::view {

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit
};

struct MoveInput {
  glm::vec3 axes{0.0f};  // x right, y up, z forward; each -1, 0 or 1
  bool fast = false;     // shift
};

class FlyCamera {
 public:
  // Starts where `camera` is, looking at its target.
  void look_from(const Camera& camera);
  // Mouse look: a drag of `pixels` turns the view (0.2 degrees a pixel).
  void turn(glm::vec2 pixels);
  void move(const MoveInput& input, double seconds);
  // The wheel: each notch multiplies the speed by 1.25, within [0.5, 200] m/s.
  void scale_speed(double notches);
  float speed() const { return speed_; }
  Camera camera() const;

 private:
  glm::vec3 forward() const;

  glm::vec3 position_{0.0f, 10.0f, -30.0f};
  float yaw_ = 0.0f;    // radians about +Y; 0 looks along -Z
  float pitch_ = 0.0f;  // radians, up positive
  float speed_ = 8.0f;  // metres per second
  float fov_y_deg_ = 50.0f;
  float near_ = 0.1f;
  float far_ = 1000.0f;
};

// The world ray through the centre of pixel `pixel` (top-left origin) of `view`.
Ray pixel_ray(const View& view, glm::vec2 pixel);

}  // namespace siviflow::view
