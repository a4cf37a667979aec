// The viewer's image transitions: one colour image from one state to the next.
#pragma once

#include "siviflow/renderer.h"

namespace siviflow::view {

// Records a barrier taking the colour image `image` from `from` to `to` (stages, accesses and
// layouts as the ImageStates say).
void image_barrier(VkCommandBuffer cmd, VkImage image, const ImageState& from, const ImageState& to);

}  // namespace siviflow::view
