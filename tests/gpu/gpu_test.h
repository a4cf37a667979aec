// Fixture of every GPU test: a headless context on lavapipe with the validation layer and
// synchronization validation; any validation error fails the test, and a missing layer or a
// device other than llvmpipe is a failure, never a skip.
#pragma once

#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "siviflow/headless_context.h"
#include "siviflow/renderer.h"

namespace siviflow::testing {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    HeadlessContextOptions options;
    options.enable_validation = true;
    options.require_validation = true;
    options.require_lavapipe = std::getenv("SIVIFLOW_EXPECT_LAVAPIPE") != nullptr;
    const Status status = HeadlessContext::create(options, &context_);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_TRUE(context_->report().validation_enabled);
  }

  void TearDown() override {
    renderer_.reset();  // its destruction is validated too
    if (context_ == nullptr) return;
    std::string messages;
    for (const std::string& message : context_->validation_errors()) messages += message + "\n";
    EXPECT_EQ(context_->validation_error_count(), 0u) << messages;
  }

  CreateInfo make_create_info(uint32_t width, uint32_t height) const {
    CreateInfo info = context_->renderer_create_info({width, height}, VK_FORMAT_R16G16B16A16_SFLOAT);
    info.frames_in_flight = 2;
    info.enable_readback = true;
    return info;
  }

  std::unique_ptr<HeadlessContext> context_;
  std::unique_ptr<Renderer> renderer_;
};

}  // namespace siviflow::testing
