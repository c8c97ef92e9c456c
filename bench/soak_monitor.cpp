// Watches a running detector nodelet through /diagnostics during a long run and prints, every
// 500 processed frames, the nodelet manager's resident memory next to the detector's own
// figures; ends after ~frames with the growth after warm-up. Prints figures; not a test.
// Usage: soak_monitor _manager_pid:=PID _frames:=10000
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <string>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>

namespace
{
double residentMegabytes(int pid)
{
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6) / 1024.0;
  return -1.0;
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "soak_monitor");
  ros::NodeHandle nh, private_nh("~");
  int pid = 0, frames = 10000;
  private_nh.param("manager_pid", pid, 0);
  private_nh.param("frames", frames, 10000);
  std::mutex mutex;
  std::map<std::string, std::string> values;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& status : m->status)
          if (status.name.find("plane map") != std::string::npos)
            for (const auto& kv : status.values) values[kv.key] = kv.value;
      });
  std::printf("frames   manager RSS MB   Hough MB   chunks   planes   ms/frame   skipped   queue drops\n");
  const int warmup = std::min(1000, frames / 4);
  double rss_warm = -1, rss_max = 0, rss_end = 0;
  int next_report = 0, processed = 0;
  const ros::WallTime start = ros::WallTime::now();
  while (ros::ok() && processed < frames)
  {
    ros::spinOnce();
    ros::WallDuration(0.1).sleep();
    std::lock_guard<std::mutex> lock(mutex);
    if (values.count("frames processed") == 0) continue;
    processed = std::stoi(values["frames processed"]);
    if (processed < next_report) continue;
    const double rss = residentMegabytes(pid);
    if (processed >= warmup && rss_warm < 0 && rss > 0) rss_warm = rss;
    if (processed >= warmup) rss_max = std::max(rss_max, rss);
    rss_end = rss;
    std::printf("%6d   %14.1f   %8s   %6s   %6s   %8s   %7s   %11s\n", processed, rss, values["Hough space MB"].c_str(),
                values["Hough chunks"].c_str(), values["planes"].c_str(), values["ms per frame (last)"].c_str(),
                values["frames skipped (no transform)"].c_str(),
                values["frames dropped (queue full, detector behind)"].c_str());
    std::fflush(stdout);
    next_report = (processed / 500 + 1) * 500;
  }
  std::printf("%d frames in %.0f s; manager RSS after %d frames %.1f MB, at the end %.1f MB, highest after warm-up "
              "%.1f MB (growth %+.1f MB)\n",
              processed, (ros::WallTime::now() - start).toSec(), warmup, rss_warm, rss_end, rss_max,
              rss_end - rss_warm);
  return processed >= frames ? 0 : 1;
}
