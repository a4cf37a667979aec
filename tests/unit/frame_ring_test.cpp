// The frame ring's CPU parts: the per-slot linear allocator and the deferred deletions.
#include <vector>

#include <gtest/gtest.h>

#include "vk/frame_ring.h"

namespace siviflow {
namespace {

TEST(LinearAllocator, AlignsAndFillsToCapacity) {
  LinearAllocator allocator(64);
  VkDeviceSize offset = 99;
  ASSERT_TRUE(allocator.allocate(3, 4, &offset));
  EXPECT_EQ(offset, 0u);
  ASSERT_TRUE(allocator.allocate(8, 16, &offset));
  EXPECT_EQ(offset, 16u);  // 3 rounded up to the 16-byte boundary
  EXPECT_EQ(allocator.used(), 24u);
  ASSERT_TRUE(allocator.allocate(40, 8, &offset));
  EXPECT_EQ(offset, 24u);
  EXPECT_EQ(allocator.used(), 64u);
  EXPECT_FALSE(allocator.allocate(1, 1, &offset));
  EXPECT_EQ(allocator.used(), 64u) << "a failed allocation must not move the cursor";
  allocator.reset();
  ASSERT_TRUE(allocator.allocate(64, 1, &offset));
  EXPECT_EQ(offset, 0u);
}

TEST(LinearAllocator, HugeRequestsDoNotWrapAround) {
  LinearAllocator allocator(1024);
  VkDeviceSize offset = 0;
  ASSERT_TRUE(allocator.allocate(100, 1, &offset));
  EXPECT_FALSE(allocator.allocate(~VkDeviceSize{0} - 50, 1, &offset));
  EXPECT_FALSE(allocator.allocate(925, 1, &offset));
  EXPECT_TRUE(allocator.allocate(924, 1, &offset));
}

TEST(LinearAllocator, RefusesAlignmentThatIsNotAPowerOfTwo) {
  LinearAllocator allocator(64);
  VkDeviceSize offset = 0;
  ASSERT_TRUE(allocator.allocate(3, 1, &offset));
  EXPECT_FALSE(allocator.allocate(4, 0, &offset));
  EXPECT_FALSE(allocator.allocate(4, 12, &offset));
  EXPECT_EQ(allocator.used(), 3u);
}

TEST(DeferredDeletions, RunInOrderOnceThenEmpty) {
  DeferredDeletions deletions;
  std::vector<int> order;
  deletions.defer([&] { order.push_back(1); });
  deletions.defer([&] { order.push_back(2); });
  EXPECT_EQ(deletions.pending(), 2u);
  EXPECT_TRUE(order.empty()) << "nothing runs before the slot comes round again";
  deletions.run_all();
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
  EXPECT_EQ(deletions.pending(), 0u);
  deletions.run_all();
  EXPECT_EQ(order.size(), 2u);
}

}  // namespace
}  // namespace siviflow
