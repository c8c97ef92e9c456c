#include <gtest/gtest.h>

#include "hough_plane_detector/sim/room_statistics.h"

using namespace hough_plane_detector;

namespace
{
// Forty rooms of ten scored frames and 50 visible planes; `false_in` gives each room's false planes.
template <typename FalseIn>
std::vector<RoomCounts> rooms(int detected, FalseIn false_in)
{
  std::vector<RoomCounts> all;
  for (int i = 0; i < 40; ++i)
    all.push_back({"seed " + std::to_string(600 + i), detected, 50, false_in(i), 10});
  return all;
}
}  // namespace

// The pooled figures are the plain ratios; rooms that all agree leave no room for another
// sample to differ, rooms that disagree do, and the interval holds the pooled figure.
TEST(RoomStatistics, PooledFiguresAndTheirSpreadOverRooms)
{
  const RoomFigures same = roomFigures(rooms(47, [](int) { return 1; }));
  EXPECT_DOUBLE_EQ(same.found_percent.value, 94.0);
  EXPECT_DOUBLE_EQ(same.false_per_frame.value, 0.1);
  EXPECT_DOUBLE_EQ(same.false_per_frame.low, 0.1);
  EXPECT_DOUBLE_EQ(same.false_per_frame.high, 0.1);

  // The same 40 false planes, all in four rooms: the rate is the same, far less certain.
  const RoomFigures clustered = roomFigures(rooms(47, [](int i) { return i % 10 == 0 ? 10 : 0; }));
  EXPECT_DOUBLE_EQ(clustered.false_per_frame.value, 0.1);
  EXPECT_LT(clustered.false_per_frame.low, 0.05);
  EXPECT_GT(clustered.false_per_frame.high, 0.15);
  EXPECT_LE(clustered.false_per_frame.low, clustered.false_per_frame.value);
  EXPECT_GE(clustered.false_per_frame.high, clustered.false_per_frame.value);
}

// A change that removes a false plane in every room is an effect whose interval excludes zero;
// one that removes the same number in one room is not, though the pooled difference is the same.
// Rooms scored only before or only after are left out of the pairing.
TEST(RoomStatistics, AnEffectOneRoomCarriesReachesAcrossZero)
{
  const std::vector<RoomCounts> before = rooms(47, [](int i) { return i % 10 == 0 ? 41 : 1; });
  const RoomEffect everywhere = pairedRoomEffect(before, rooms(47, [](int i) { return i % 10 == 0 ? 40 : 0; }));
  EXPECT_EQ(everywhere.rooms, 40);
  EXPECT_EQ(everywhere.rooms_changed, 40);
  EXPECT_NEAR(everywhere.false_per_frame.value, -0.1, 1e-12);
  EXPECT_LT(everywhere.false_per_frame.high, 0.0);
  EXPECT_DOUBLE_EQ(everywhere.found_percent.value, 0.0);

  std::vector<RoomCounts> one_room = before;
  one_room[0].false_detections -= 40;
  one_room.push_back({"seed 999", 50, 50, 0, 10});  // not scored before: not paired
  const RoomEffect concentrated = pairedRoomEffect(before, one_room);
  EXPECT_EQ(concentrated.rooms, 40);
  EXPECT_EQ(concentrated.rooms_changed, 1);
  EXPECT_NEAR(concentrated.false_per_frame.value, -0.1, 1e-12);
  EXPECT_LT(concentrated.false_per_frame.low, -0.1);
  EXPECT_GE(concentrated.false_per_frame.high, 0.0);

  const RoomEffect found = pairedRoomEffect(before, rooms(48, [](int i) { return i % 10 == 0 ? 41 : 1; }));
  EXPECT_NEAR(found.found_percent.value, 2.0, 1e-12);
  EXPECT_GT(found.found_percent.low, 0.0);
}
