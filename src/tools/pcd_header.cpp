#include "hough_plane_detector/tools/pcd_header.h"

#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace hough_plane_detector
{

std::string checkPcdHeader(std::istream& in)
{
  // PCL's reader reads on past a missing key (and may crash doing so): every key the format
  // requires is checked here first, in a bounded read.
  std::map<std::string, std::vector<std::string>> keys;
  std::string line;
  for (int number = 1; number <= 64 && std::getline(in, line); ++number)
  {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key, word;
    words >> key;
    static const std::set<std::string> known = {"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH",
                                                "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
    if (!known.count(key))
      return "not a PCD header: line " + std::to_string(number) + " starts with '" + line.substr(0, 24) + "'";
    while (words >> word) keys[key].push_back(word);
    if (key != "DATA") continue;
    for (const char* required : {"FIELDS", "SIZE", "TYPE", "WIDTH", "HEIGHT", "POINTS"})
      if (keys[required].empty()) return std::string("PCD header has no ") + required;
    const size_t fields = keys["FIELDS"].size();
    if (keys["SIZE"].size() != fields || keys["TYPE"].size() != fields || (keys.count("COUNT") && keys["COUNT"].size() != fields))
      return "PCD header lists " + std::to_string(fields) + " FIELDS but SIZE, TYPE or COUNT differ in number";
    long long width = 0, height = 0, points = 0;
    try
    {
      width = std::stoll(keys["WIDTH"][0]);
      height = std::stoll(keys["HEIGHT"][0]);
      points = std::stoll(keys["POINTS"][0]);
    }
    catch (const std::exception&)
    {
      return "PCD header's WIDTH, HEIGHT or POINTS is not a number";
    }
    constexpr long long kMaxSide = 1 << 20;  // no sensor is wider; also keeps width * height exact
    if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide || points != width * height)
      return "PCD header's WIDTH x HEIGHT (" + std::to_string(width) + " x " + std::to_string(height) +
             ") does not match POINTS (" + std::to_string(points) + ")";
    const std::string data = keys["DATA"].empty() ? "" : keys["DATA"][0];
    if (data != "ascii" && data != "binary" && data != "binary_compressed")
      return "PCD header's DATA is '" + data + "', not ascii, binary or binary_compressed";
    return "";
  }
  return "not a PCD header: no DATA line in its first 64 lines";
}

}  // namespace hough_plane_detector
