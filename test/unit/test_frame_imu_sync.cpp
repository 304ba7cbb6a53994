// FrameImuSynchronizer: frames wait for the IMU to pass them, queues are bounded,
// late data is dropped, the released IMU is what the offline runner feeds, and the IMU's
// clock jumping back starts a new run.
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
  ASSERT_EQ(sync.addFrame(50 * kMs, 1), FrameAdded::kQueued);
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
  EXPECT_EQ(sync.addImu(imuAt(10 * kMs)), ImuAdded::kLate);
  EXPECT_EQ(sync.addImu(imuAt(5 * kMs)), ImuAdded::kLate);
  EXPECT_EQ(sync.counts().imu_late, 2u);
  sync.addFrame(8 * kMs, 1);
  ASSERT_TRUE(sync.pop());
  EXPECT_EQ(sync.addFrame(8 * kMs, 2), FrameAdded::kLate) << "same stamp as a released frame";
  EXPECT_EQ(sync.addFrame(4 * kMs, 3), FrameAdded::kLate) << "older than a released frame";
  sync.addFrame(20 * kMs, 4);
  EXPECT_EQ(sync.addFrame(15 * kMs, 5), FrameAdded::kLate) << "older than a waiting frame";
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

namespace {
// A bag of 8-16 s played again: IMU every 5 ms, frames every 50 ms, frames released up to 15.9 s.
FrameImuSynchronizer<int> firstPlayUpTo16s() {
  FrameImuSynchronizer<int> sync;
  for (int64_t t = 8000; t <= 15950; t += 50) sync.addFrame(t * kMs, static_cast<int>(t));
  for (int64_t t = 7995; t <= 16000; t += 5) sync.addImu(imuAt(t * kMs));
  while (sync.pop()) {
  }
  return sync;
}
}  // namespace

TEST(FrameImuSync, TheImuClockJumpingBackStartsANewRun) {
  FrameImuSynchronizer<int> sync = firstPlayUpTo16s();
  sync.addFrame(15980 * kMs, 1);  // waits for the old clock's IMU, which has ended
  EXPECT_EQ(sync.addImu(imuAt(15950 * kMs)), ImuAdded::kLate) << "a small step back is late";
  ASSERT_GT(sync.counts().imu_late, 0u);
  ASSERT_EQ(sync.addImu(imuAt(7995 * kMs)), ImuAdded::kNewRun);
  EXPECT_EQ(sync.lastClockJumpNs(), (16000 - 7995) * kMs);
  EXPECT_EQ(sync.waitingFrames(), 0u) << "the old clock's waiting frame is not part of the new run";
  EXPECT_EQ(sync.waitingImu(), 1u) << "the new clock's first sample is kept";
  EXPECT_EQ(sync.counts().imu_late, 0u) << "a new run counts afresh";
  EXPECT_EQ(sync.addImu(imuAt(8000 * kMs)), ImuAdded::kQueued);
  EXPECT_EQ(sync.addFrame(8000 * kMs, 2), FrameAdded::kQueued)
      << "the new run's frames are not late against the old run's";
  sync.addImu(imuAt(8005 * kMs));
  auto ready = sync.pop();
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->frame, 2);
  EXPECT_EQ(ready->imu.size(), 3u);
}

TEST(FrameImuSync, TheOldClocksLastFrameAfterTheImusJumpDoesNotHoldBackTheNewRun) {
  // Stop 67's bug in the tracker nodelet: a bag cut at 16 s has no IMU sample after its last
  // image, which reached the queue after the IMU's jump and waited there for ever.
  FrameImuSynchronizer<int> sync = firstPlayUpTo16s();
  ASSERT_EQ(sync.addImu(imuAt(7995 * kMs)), ImuAdded::kNewRun);
  EXPECT_EQ(sync.addFrame(16000 * kMs, 1), FrameAdded::kOldClock);
  EXPECT_EQ(sync.addFrame(8000 * kMs, 2), FrameAdded::kQueued);
  sync.addFrame(8050 * kMs, 4);
  for (int64_t t = 8000; t <= 8055; t += 5) sync.addImu(imuAt(t * kMs));
  auto first = sync.pop();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->frame, 2);
  EXPECT_EQ(sync.pop()->frame, 4);
  EXPECT_EQ(sync.counts().frames_old_clock, 1u);
  EXPECT_EQ(sync.counts().droppedFrames(), 0u) << "the old run's frame is not the new run's drop";
}

TEST(FrameImuSync, AFrameOnTheNewClockBeforeTheImusJumpIsHeldForTheNewRun) {
  FrameImuSynchronizer<int> sync = firstPlayUpTo16s();
  EXPECT_EQ(sync.addFrame(8000 * kMs, 1), FrameAdded::kHeld);
  sync.addImu(imuAt(16005 * kMs));  // the old clock's IMU goes on
  EXPECT_FALSE(sync.pop()) << "a held frame is not released on the old clock's IMU";
  EXPECT_EQ(sync.addFrame(8050 * kMs, 2), FrameAdded::kHeld);
  EXPECT_EQ(sync.addFrame(8020 * kMs, 3), FrameAdded::kLate);
  EXPECT_EQ(sync.heldFrames(), 2u);
  ASSERT_EQ(sync.addImu(imuAt(7995 * kMs)), ImuAdded::kNewRun);
  EXPECT_EQ(sync.heldFrames(), 0u);
  EXPECT_EQ(sync.waitingFrames(), 2u);
  EXPECT_EQ(sync.addFrame(8100 * kMs, 4), FrameAdded::kQueued);
  for (int64_t t = 8000; t <= 8105; t += 5) sync.addImu(imuAt(t * kMs));
  for (int frame : {1, 2, 4}) {
    auto ready = sync.pop();
    ASSERT_TRUE(ready);
    EXPECT_EQ(ready->frame, frame);
  }
  EXPECT_EQ(sync.counts().frames_old_clock, 0u);
}

TEST(FrameImuSync, HeldFramesFollowedByTheImusClockWereStragglers) {
  FrameImuSynchronizer<int> sync = firstPlayUpTo16s();
  EXPECT_EQ(sync.addFrame(15500 * kMs, 1), FrameAdded::kHeld) << "reordered by 0.45 s";
  EXPECT_EQ(sync.addFrame(16000 * kMs, 2), FrameAdded::kQueued);
  EXPECT_EQ(sync.heldFrames(), 0u);
  EXPECT_EQ(sync.counts().frames_late, 1u);
  sync.addImu(imuAt(16005 * kMs));
  EXPECT_EQ(sync.pop()->frame, 2);
}

TEST(FrameImuSync, ACameraFarBehindTheImuAfterTheImusJumpIsNotHeld) {
  FrameImuSynchronizer<int> sync = firstPlayUpTo16s();
  for (int64_t t = 7995; t <= 8500; t += 5) sync.addImu(imuAt(t * kMs));  // the IMU races ahead
  EXPECT_EQ(sync.addFrame(8000 * kMs, 1), FrameAdded::kQueued)
      << "the IMU jumped already: nothing to wait for";
  EXPECT_EQ(sync.pop()->frame, 1);
}
