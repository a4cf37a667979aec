// The capture's motion AOV: the screen motion of the nearest surface at each pixel, from the
// frame's depth and the cameras of the frames before and after it (the capture replays its camera
// path, so the neighbours' cameras are known without rendering them). The world is static but
// for the boulders that stand for keyed obstacles and the floats, which move rigidly; the water
// surface stays where it is however its flow runs.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/renderer.h"

namespace siviflow {

// A boulder or a float where it is in the previous, this and the next frame. A boulder's shape is
// an ellipsoid of these radii around its centre (the world's boulders are bumped ellipsoids
// within them); a float's an upright cylinder of radius radii.x from centre.y - radii.y to
// centre.y + radii.y, which holds it whichever way it is turned.
struct MovingBody {
  glm::vec3 previous_centre{0.0f};
  glm::vec3 centre{0.0f};
  glm::vec3 next_centre{0.0f};
  glm::vec3 radii{1.0f};
  bool upright_cylinder = false;
};

struct MotionFrame {
  uint32_t width = 0;
  uint32_t height = 0;
  const float* window_depth = nullptr;  // width * height, standard depth 0 near .. 1 far (sky)
  const float* water_mask = nullptr;    // width * height, 1 where the (still) water is seen
  View previous;  // the views of the frames before and after, and this frame's
  View current;
  View next;
  std::span<const MovingBody> bodies;  // the boulders and floats that move about this frame
};

// Writes 4 floats per pixel into `xyzw` (resized), in Blender's Vector pass layout: X, Y = where
// the surface seen in the pixel was in the previous frame minus where it is now; Z, W = where it
// is now minus where it will be in the next frame; in pixels (rounded to 1/1024, within ±65504),
// x right, y up. Sky pixels move with the camera's rotation alone; a point behind a neighbour's
// camera has no motion (0). A point that is not water and lies within a moving body's reach moves
// with it.
void compute_motion(const MotionFrame& frame, std::vector<float>* xyzw);

}  // namespace siviflow
