#include "hough_plane_detector/core/thread_team.h"

#include <algorithm>

namespace hough_plane_detector
{

ThreadTeam::ThreadTeam(int members) : members_(std::max(1, members))
{
  for (int member = 1; member < members_; ++member) helpers_.emplace_back([this, member] { helperLoop(member); });
}

ThreadTeam& ThreadTeam::callingThreadOnly()
{
  static ThreadTeam alone(1);
  return alone;
}

ThreadTeam::~ThreadTeam()
{
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (auto& helper : helpers_) helper.join();
}

void ThreadTeam::takeItems(int member)
{
  for (int index = next_.fetch_add(1, std::memory_order_relaxed); index < n_;
       index = next_.fetch_add(1, std::memory_order_relaxed))
    (*work_)(index, member);
}

void ThreadTeam::forEach(int n, const Work& work)
{
  if (n <= 0) return;
  if (members_ == 1)
  {
    for (int index = 0; index < n; ++index) work(index, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    work_ = &work;
    n_ = n;
    next_.store(0, std::memory_order_relaxed);
    busy_helpers_ = members_ - 1;
    ++generation_;
  }
  start_.notify_all();
  takeItems(0);
  // Helpers that woke late find no items left and report at once.
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return busy_helpers_ == 0; });
  work_ = nullptr;
}

void ThreadTeam::helperLoop(int member)
{
  long joined = 0;
  for (;;)
  {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stopping_ || generation_ != joined; });
      if (stopping_) return;
      joined = generation_;
    }
    takeItems(member);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (--busy_helpers_ == 0) done_.notify_one();
    }
  }
}

}  // namespace hough_plane_detector
