// The threading contract of renderer.h, held under ThreadSanitizer (the CI builds this test with
// -DSIVIFLOW_SANITIZE=thread and runs it as the `thread` tier): a host that calls begin_frame and
// update on a simulation thread and records on its render thread, handing each frame over in
// order, gets the same pixels as one thread; a renderer of another river simulating on its own
// thread meanwhile changes neither; and a physics thread querying the water while the render
// thread records gets the answers one thread gets, and changes no pixel. lavapipe is not instrumented, so what TSan judges is our
// library's own memory across the host's threads.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <shared_mutex>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "render_frames.h"

namespace siviflow::testing {
namespace {

// One thread that runs the jobs handed to it, one at a time; run() returns when the job is done,
// so the caller and the worker take turns, ordered by the mutex.
class WorkerThread {
 public:
  WorkerThread() : thread_([this] { loop(); }) {}
  ~WorkerThread() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  void run(const std::function<void()>& job) {
    std::unique_lock lock(mutex_);
    job_ = &job;
    changed_.notify_all();
    changed_.wait(lock, [this] { return job_ == nullptr; });
  }
  std::thread::id id() const { return thread_.get_id(); }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [this] { return stop_ || job_ != nullptr; });
      if (job_ == nullptr) return;
      (*job_)();
      job_ = nullptr;
      changed_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  const std::function<void()>* job_ = nullptr;
  bool stop_ = false;
  std::thread thread_;  // last: starts once the members it uses exist
};

constexpr uint32_t kFrames = 24;

void expect_same_frames(const std::vector<Frame>& expected, const std::vector<Frame>& actual,
                        uint32_t first_frame) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(expected[i].rgba, actual[i].rgba) << "frame " << first_frame + i;
    EXPECT_EQ(expected[i].particle_aux, actual[i].particle_aux) << "frame " << first_frame + i;
  }
}

class ThreadHandoffTest : public RenderTest {};

TEST_F(ThreadHandoffTest, UpdateOnSimulationThreadRecordOnRenderThread) {
  const std::vector<Frame> one_thread = render(0, kFrames);

  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  WorkerThread simulation;
  bool on_worker = true;
  run_cpu_part_ = [&](const std::function<void()>& part) {
    simulation.run([&] {
      on_worker = on_worker && std::this_thread::get_id() == simulation.id();
      part();
    });
  };
  const std::vector<Frame> handed_over = render(0, kFrames);
  EXPECT_TRUE(on_worker);
  expect_same_frames(one_thread, handed_over, 0);
}

TEST_F(ThreadHandoffTest, AnotherRiverSimulatesOnItsOwnThreadMeanwhile) {
  // A second renderer of its own river (not shared), on the same device and world.
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.reflection = &World::draw_reflection;
  info.reflection_user = world_.get();
  std::unique_ptr<Renderer> other;
  ASSERT_TRUE(Renderer::create(info, &other).ok());
  ASSERT_TRUE(other->set_occluders(world_->occluders()).ok());
  std::vector<View> views;
  for (uint32_t frame = 0; frame < kFrames; ++frame) {
    views.push_back(camera_view(world_->scene_camera(frame / 30.0), {kWidth, kHeight}));
  }

  // It simulates frames 0..kFrames-1 on its thread while this one renders them with the first.
  Status simulated;
  std::thread simulation([&] {
    for (uint32_t frame = 0; frame < kFrames && simulated.ok(); ++frame) {
      simulated = other->simulate(views[frame], frame / 30.0);
    }
  });
  const std::vector<Frame> first = render(0, kFrames + 2);
  simulation.join();
  ASSERT_TRUE(simulated.ok()) << simulated.message();

  // Then its next two frames equal the first renderer's.
  renderer_.swap(other);
  const std::vector<Frame> second = render(kFrames, kFrames + 2);
  expect_same_frames({first.end() - 2, first.end()}, second, kFrames);
  renderer_.swap(other);
}

TEST_F(ThreadHandoffTest, QueriesOnAPhysicsThreadWhileTheRenderThreadRecords) {
  const std::vector<Frame> one_thread = render(0, kFrames);

  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  std::vector<glm::vec3> points;
  for (float z = -100.0f; z <= 100.0f; z += 2.5f) {
    for (float x = -20.0f; x <= 19.0f; x += 1.5f) points.push_back({x, 1.0f, z});
  }
  std::vector<WaterSample> expected(points.size());
  ASSERT_TRUE(renderer_->query_water(points, expected).ok());
  // The host's rule: queries never overlap the calls that change the flow (begin_frame and
  // update, where the keyed boulder moves); they do overlap record and the GPU's work.
  std::shared_mutex flow_changes;
  run_cpu_part_ = [&](const std::function<void()>& part) {
    std::unique_lock lock(flow_changes);
    part();
  };
  std::atomic<bool> done{false};
  size_t rounds = 0, differing = 0;
  Status queried;
  std::thread physics([&] {
    std::vector<WaterSample> samples(points.size());
    while (!done.load() && queried.ok()) {
      std::shared_lock lock(flow_changes);
      queried = renderer_->query_water(points, samples);
      for (size_t i = 0; i < points.size(); ++i) {
        differing += samples[i].velocity != expected[i].velocity || samples[i].wet != expected[i].wet;
      }
      ++rounds;
    }
  });
  const std::vector<Frame> with_queries = render(0, kFrames);
  done = true;
  physics.join();
  ASSERT_TRUE(queried.ok()) << queried.message();
  EXPECT_GT(rounds, 0u);
  EXPECT_EQ(differing, 0u);  // the keyed boulder rolls in only after 1 s: the flow stays put
  expect_same_frames(one_thread, with_queries, 0);
}

}  // namespace
}  // namespace siviflow::testing
