#include "hough_plane_detector/sim/room_statistics.h"

#include <algorithm>
#include <map>
#include <random>

namespace hough_plane_detector
{

namespace
{
constexpr unsigned kBootstrapSeed = 20141;  // fixed: the same rooms give the same interval

struct Pooled
{
  double detected = 0.0, visible = 0.0, false_detections = 0.0, frames = 0.0;
  void add(const RoomCounts& r, double sign = 1.0)
  {
    detected += sign * r.detected;
    visible += sign * r.visible;
    false_detections += sign * r.false_detections;
    frames += sign * r.frames;
  }
};

double percent(const Pooled& p) { return p.visible > 0.0 ? 100.0 * p.detected / p.visible : 0.0; }
double perFrame(const Pooled& p) { return p.frames > 0.0 ? p.false_detections / p.frames : 0.0; }

// The 2.5 and 97.5 percentiles of the samples.
void percentiles(std::vector<double>& samples, RoomInterval& interval)
{
  if (samples.empty()) return;
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double q) { return samples[static_cast<size_t>(q * (samples.size() - 1) + 0.5)]; };
  interval.low = at(0.025);
  interval.high = at(0.975);
}

// Resamples room indices with replacement and hands each resample to `figures`.
template <typename Figures>
void bootstrap(size_t rooms, int resamples, Figures figures)
{
  std::mt19937 rng(kBootstrapSeed);
  std::uniform_int_distribution<size_t> pick(0, rooms - 1);
  std::vector<size_t> drawn(rooms);
  for (int r = 0; r < resamples; ++r)
  {
    for (size_t& i : drawn) i = pick(rng);
    figures(drawn);
  }
}
}  // namespace

RoomFigures roomFigures(const std::vector<RoomCounts>& rooms, int resamples)
{
  RoomFigures figures;
  Pooled all;
  for (const RoomCounts& r : rooms) all.add(r);
  figures.found_percent.value = figures.found_percent.low = figures.found_percent.high = percent(all);
  figures.false_per_frame.value = figures.false_per_frame.low = figures.false_per_frame.high = perFrame(all);
  if (rooms.empty() || resamples <= 0) return figures;
  std::vector<double> found, false_rate;
  bootstrap(rooms.size(), resamples, [&](const std::vector<size_t>& drawn) {
    Pooled p;
    for (size_t i : drawn) p.add(rooms[i]);
    found.push_back(percent(p));
    false_rate.push_back(perFrame(p));
  });
  percentiles(found, figures.found_percent);
  percentiles(false_rate, figures.false_per_frame);
  return figures;
}

RoomEffect pairedRoomEffect(const std::vector<RoomCounts>& before, const std::vector<RoomCounts>& after, int resamples)
{
  std::map<std::string, const RoomCounts*> earlier;
  for (const RoomCounts& r : before) earlier[r.room] = &r;
  std::vector<std::pair<RoomCounts, RoomCounts>> pairs;
  for (const RoomCounts& r : after)
  {
    const auto it = earlier.find(r.room);
    if (it != earlier.end()) pairs.emplace_back(*it->second, r);
  }
  RoomEffect effect;
  effect.rooms = static_cast<int>(pairs.size());
  for (const auto& [b, a] : pairs)
    if (a.detected != b.detected || a.false_detections != b.false_detections) ++effect.rooms_changed;
  // The pooled figure after less the pooled figure before, over one draw of the paired rooms.
  auto difference = [&](const std::vector<size_t>& drawn, double& found, double& false_rate) {
    Pooled b, a;
    for (size_t i : drawn)
    {
      b.add(pairs[i].first);
      a.add(pairs[i].second);
    }
    found = percent(a) - percent(b);
    false_rate = perFrame(a) - perFrame(b);
  };
  std::vector<size_t> everyone(pairs.size());
  for (size_t i = 0; i < everyone.size(); ++i) everyone[i] = i;
  difference(everyone, effect.found_percent.value, effect.false_per_frame.value);
  effect.found_percent.low = effect.found_percent.high = effect.found_percent.value;
  effect.false_per_frame.low = effect.false_per_frame.high = effect.false_per_frame.value;
  if (pairs.empty() || resamples <= 0) return effect;
  std::vector<double> found, false_rate;
  bootstrap(pairs.size(), resamples, [&](const std::vector<size_t>& drawn) {
    double f = 0.0, r = 0.0;
    difference(drawn, f, r);
    found.push_back(f);
    false_rate.push_back(r);
  });
  percentiles(found, effect.found_percent);
  percentiles(false_rate, effect.false_per_frame);
  return effect;
}

}  // namespace hough_plane_detector
