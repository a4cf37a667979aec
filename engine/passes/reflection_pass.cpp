#include "passes/passes.h"

#include "vk/pipeline.h"

namespace siviflow {

DataHandle<ReflectionView> add_reflection_pass(FrameGraph& graph, ImageHandle* color,
                                               ImageHandle* depth, ReflectionCallback callback,
                                               void* user) {
  const DataHandle<ReflectionView> view = graph.declare_data<ReflectionView>("reflection view");
  PassBuilder pass = graph.add_pass("reflection", PassKind::Graphics);
  *color = pass.color_write(*color, LoadOp::Clear);
  *depth = pass.depth_write(*depth, LoadOp::Clear);
  if (callback == nullptr) return view;
  const ImageHandle target = *color;
  pass.record([view, target, callback, user](const PassContext& ctx) {
    ReflectionView mirrored = ctx.data(view);
    mirrored.extent = ctx.extent(target);
    set_viewport(ctx.table(), ctx.cmd(), mirrored.extent);
    ctx.table().vkCmdSetScissor(ctx.cmd(), 0, 1, &mirrored.area);  // what the water samples
    callback(ctx.cmd(), mirrored, user);
    return Status::success();
  });
  return view;
}

}  // namespace siviflow
