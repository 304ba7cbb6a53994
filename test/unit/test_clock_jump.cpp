// The clock-jump watcher the nodelets start new runs on.
#include <gtest/gtest.h>

#include "alvio/common/clock_jump.h"

namespace {

constexpr int64_t kMs = 1'000'000;

TEST(ClockWatch, TellsAJumpBackOnceAndFollowsTheNewClock) {
  alvio::ClockWatch clock;
  EXPECT_EQ(clock.follow(10'000 * kMs), 0);  // the first stamp is no jump
  EXPECT_EQ(clock.follow(10'005 * kMs), 0);
  // A late or reordered message (less than kClockJumpBackNs back) is no jump, and does not move
  // the newest stamp back.
  EXPECT_EQ(clock.follow(9'900 * kMs), 0);
  EXPECT_EQ(clock.newest(), 10'005 * kMs);
  // A bag played again: the jump is measured from the newest stamp, and the new clock is followed
  // from where it jumped to.
  EXPECT_EQ(clock.follow(1'000 * kMs), 9'005 * kMs);
  EXPECT_EQ(clock.newest(), 1'000 * kMs);
  EXPECT_EQ(clock.follow(1'005 * kMs), 0);
  EXPECT_EQ(clock.newest(), 1'005 * kMs);
  // Exactly kClockJumpBackNs back is still a late message.
  EXPECT_EQ(clock.follow(1'005 * kMs - alvio::kClockJumpBackNs), 0);
  EXPECT_EQ(clock.follow(1'005 * kMs - alvio::kClockJumpBackNs - 1), alvio::kClockJumpBackNs + 1);
}

TEST(ClockWatch, MessagesFromBeforeTheJumpLieAheadOfTheNewClock) {
  alvio::ClockWatch clock;
  EXPECT_FALSE(clock.aheadByAJump(5'000 * kMs)) << "nothing followed yet";
  clock.follow(5'000 * kMs);
  clock.follow(1'000 * kMs);  // jumped back 4 s
  EXPECT_TRUE(clock.aheadByAJump(4'990 * kMs)) << "a frame queued on the old clock";
  EXPECT_FALSE(clock.aheadByAJump(1'000 * kMs + alvio::kClockJumpBackNs));
  EXPECT_FALSE(clock.aheadByAJump(900 * kMs)) << "behind the newest stamp is not ahead";
}

TEST(ClockWatch, ALaggingStreamIsDroppedUntilItsFirstMessageOnTheNewClock) {
  alvio::ClockWatch imu;
  imu.follow(16'000 * kMs);
  EXPECT_FALSE(imu.laggingOnOldClock(15'950 * kMs)) << "no jump yet: an image behind the IMU";
  EXPECT_FALSE(imu.laggingOnOldClock(16'500 * kMs)) << "no jump yet: an image ahead of the IMU";
  imu.follow(8'000 * kMs);  // the bag played again
  EXPECT_TRUE(imu.laggingOnOldClock(16'000 * kMs)) << "the old clock's last image";
  EXPECT_FALSE(imu.laggingOnOldClock(8'000 * kMs)) << "the new clock's first";
  // Caught up: a message far ahead of the IMU now is an IMU gap, not the old clock (the images
  // wait for the IMU as usual).
  EXPECT_FALSE(imu.laggingOnOldClock(8'500 * kMs));
  imu.follow(1'000 * kMs);  // and again
  EXPECT_TRUE(imu.laggingOnOldClock(8'500 * kMs));
}

}  // namespace
