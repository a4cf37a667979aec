// The gate itself must be able to fail: a deliberate API misuse is counted as an error.
#include <gtest/gtest.h>

#include "siviflow/headless_context.h"
#include "vk/device_table.h"

namespace siviflow::testing {
namespace {

TEST(ValidationGate, CountsAnErrorOfTheLayer) {
  HeadlessContextOptions options;
  options.enable_validation = true;
  options.require_validation = true;
  options.print_validation_messages = false;
  std::unique_ptr<HeadlessContext> context;
  const Status status = HeadlessContext::create(options, &context);
  ASSERT_TRUE(status.ok()) << status.message();
  DeviceTable table;
  const char* missing = nullptr;
  ASSERT_EQ(load_device_table(context->instance(), context->physical_device(), context->device(),
                              context->get_instance_proc_addr(), context->get_device_proc_addr(),
                              true, &table, &missing),
            VK_SUCCESS);
  // Anisotropy without enabling the samplerAnisotropy feature: VUID-VkSamplerCreateInfo-anisotropyEnable-01070.
  VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  info.anisotropyEnable = VK_TRUE;
  info.maxAnisotropy = 4.0f;
  VkSampler sampler = VK_NULL_HANDLE;
  table.vkCreateSampler(context->device(), &info, nullptr, &sampler);
  if (sampler != VK_NULL_HANDLE) table.vkDestroySampler(context->device(), sampler, nullptr);
  EXPECT_GT(context->validation_error_count(), 0u);
  ASSERT_FALSE(context->validation_errors().empty());
  EXPECT_NE(context->validation_errors()[0].find("VUID-VkSamplerCreateInfo-anisotropyEnable"),
            std::string::npos)
      << context->validation_errors()[0];
}

}  // namespace
}  // namespace siviflow::testing
