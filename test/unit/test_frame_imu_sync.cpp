// FrameImuSynchronizer: frames wait for the IMU to pass them, queues are bounded,
// late data is dropped, and the released IMU is what the offline runner feeds.
#include <gtest/gtest.h>

#include "alvio/pipeline/frame_imu_sync.h"

using namespace alvio;

namespace {
ImuSample imuAt(int64_t t_ns) {
  ImuSample s;
  s.t_ns = t_ns;
  s.acc = Eigen::Vector3d(0, 0, 9.81);
  return s;
}
constexpr int64_t kMs = 1000000;
}  // namespace

TEST(FrameImuSync, FrameWaitsForAnImuSampleAfterIt) {
  FrameImuSynchronizer<int> sync;
  for (int64_t t = 0; t <= 50 * kMs; t += 5 * kMs) sync.addImu(imuAt(t));
  ASSERT_TRUE(sync.addFrame(50 * kMs, 1));
  EXPECT_FALSE(sync.pop()) << "IMU only reaches the frame time, not past it";
  sync.addImu(imuAt(55 * kMs));
  auto ready = sync.pop();
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->frame, 1);
  EXPECT_EQ(ready->t_ns, 50 * kMs);
  ASSERT_EQ(ready->imu.size(), 12u);
  EXPECT_EQ(ready->imu.front().t_ns, 0);
  EXPECT_EQ(ready->imu.back().t_ns, 55 * kMs);
  EXPECT_FALSE(sync.pop());
  EXPECT_EQ(sync.waitingImu(), 0u);
}

TEST(FrameImuSync, FramesComeOutInOrderWithTheImuBetweenThem) {
  FrameImuSynchronizer<int> sync;
  sync.addFrame(10 * kMs, 1);
  sync.addFrame(20 * kMs, 2);
  for (int64_t t = 0; t <= 25 * kMs; t += 5 * kMs) sync.addImu(imuAt(t));
  auto a = sync.pop();
  auto b = sync.pop();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->frame, 1);
  EXPECT_EQ(b->frame, 2);
  EXPECT_EQ(a->imu.size(), 6u) << "everything received so far goes with the first frame";
  EXPECT_TRUE(b->imu.empty());
}

TEST(FrameImuSync, LateFramesAndImuAreDroppedAndCounted) {
  FrameImuSynchronizer<int> sync;
  sync.addImu(imuAt(10 * kMs));
  EXPECT_FALSE(sync.addImu(imuAt(10 * kMs)));
  EXPECT_FALSE(sync.addImu(imuAt(5 * kMs)));
  EXPECT_EQ(sync.counts().imu_late, 2u);
  sync.addFrame(8 * kMs, 1);
  ASSERT_TRUE(sync.pop());
  EXPECT_FALSE(sync.addFrame(8 * kMs, 2)) << "same stamp as a released frame";
  EXPECT_FALSE(sync.addFrame(4 * kMs, 3)) << "older than a released frame";
  sync.addFrame(20 * kMs, 4);
  EXPECT_FALSE(sync.addFrame(15 * kMs, 5)) << "older than a waiting frame";
  EXPECT_EQ(sync.counts().frames_late, 3u);
  EXPECT_EQ(sync.counts().droppedFrames(), 3u);
}

TEST(FrameImuSync, FullFrameQueueDropsTheOldest) {
  FrameImuSyncOptions options;
  options.max_frames = 3;
  FrameImuSynchronizer<int> sync(options);
  for (int i = 1; i <= 5; ++i) sync.addFrame(i * 50 * kMs, i);
  EXPECT_EQ(sync.waitingFrames(), 3u);
  EXPECT_EQ(sync.counts().frames_overflow, 2u);
  sync.addImu(imuAt(1000 * kMs));
  EXPECT_EQ(sync.pop()->frame, 3) << "frames 1 and 2 were dropped";
}

TEST(FrameImuSync, FullImuQueueDropsTheOldest) {
  FrameImuSyncOptions options;
  options.max_imu = 10;
  FrameImuSynchronizer<int> sync(options);
  for (int i = 0; i < 25; ++i) sync.addImu(imuAt(i * 5 * kMs));
  EXPECT_EQ(sync.waitingImu(), 10u);
  EXPECT_EQ(sync.counts().imu_overflow, 15u);
  sync.addFrame(100 * kMs, 1);
  auto ready = sync.pop();
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->imu.front().t_ns, 75 * kMs);
}
