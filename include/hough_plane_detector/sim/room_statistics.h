// How far a figure pooled over rendered rooms can be trusted: the rooms are a sample of the
// rooms a detector will meet, so an interval over them (a bootstrap: rooms drawn again with
// replacement) says how much another sample of rooms could move the figure, or a change's effect.
#pragma once

#include <string>
#include <vector>

namespace hough_plane_detector
{

// One room's (one camera path's) scored counts.
struct RoomCounts
{
  std::string room;  // what names it in its set (e.g. "seed 612")
  int detected = 0;
  int visible = 0;
  int false_detections = 0;
  int frames = 0;
};

// A figure and its 95 % bootstrap interval over rooms.
struct RoomInterval
{
  double value = 0.0;
  double low = 0.0;
  double high = 0.0;
};

// Found share (percent) and false planes per frame pooled over the rooms, with their intervals.
struct RoomFigures
{
  RoomInterval found_percent;
  RoomInterval false_per_frame;
};
RoomFigures roomFigures(const std::vector<RoomCounts>& rooms, int resamples = 2000);

// The effect of a change, the same rooms scored before and after (paired by `room`; rooms in
// only one of the two are left out): the differences after - before and their intervals, and
// in how many rooms anything changed. An effect that only a room or two carry has an interval
// that reaches across zero: it says little about rooms not yet seen.
struct RoomEffect
{
  RoomInterval found_percent;
  RoomInterval false_per_frame;
  int rooms = 0;          // paired
  int rooms_changed = 0;  // whose found or false counts differ
};
RoomEffect pairedRoomEffect(const std::vector<RoomCounts>& before, const std::vector<RoomCounts>& after,
                            int resamples = 2000);

}  // namespace hough_plane_detector
