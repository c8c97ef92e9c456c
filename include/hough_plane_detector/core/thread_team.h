// The calling thread and persistent helper threads sharing a frame's independent rows of work,
// so a second core helps without a thread started per frame.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hough_plane_detector
{

class ThreadTeam
{
public:
  // work(index, member): one item; `member` (0 the caller, 1.. the helpers) picks per-thread scratch.
  using Work = std::function<void(int index, int member)>;

  // `members` threads at once: the caller and members - 1 helpers.
  explicit ThreadTeam(int members = 1);
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  // A team of the calling thread alone, shared: with no helpers it keeps no state across calls.
  static ThreadTeam& callingThreadOnly();

  int size() const { return members_; }
  // Calls work once for every index in [0, n) and returns when all are done. Members take the
  // next index as they come free (rows of unequal cost stay balanced); a caller that keeps each
  // index's result apart gets the same answer for any team size.
  void forEach(int n, const Work& work);

private:
  void helperLoop(int member);
  void takeItems(int member);

  int members_;
  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  const Work* work_ = nullptr;
  int n_ = 0;
  std::atomic<int> next_{0};  // next index to take
  long generation_ = 0;       // bumped per forEach(): each helper joins each generation once
  int busy_helpers_ = 0;      // helpers still in this generation
  bool stopping_ = false;
};

}  // namespace hough_plane_detector
