// The detector's parameters are named once (HOUGH_PLANE_DETECTOR_PARAMS); their defaults are
// restated in the dynamic_reconfigure .cfg, launch/detector_params.yaml and the README table.
// This test fails when any of those drifts from DetectorParams' defaults or misses a parameter.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "hough_plane_detector/core/detector_params.h"

using namespace hough_plane_detector;

namespace
{
std::string readFile(const std::string& relative)
{
  std::ifstream in(std::string(HOUGH_SOURCE_DIR) + "/" + relative);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// name -> default of the core, as a number.
std::map<std::string, double> coreDefaults()
{
  const DetectorParams defaults;
  std::map<std::string, double> out;
#define HPD_DEFAULT(type, name) out[#name] = static_cast<double>(defaults.name);
  HOUGH_PLANE_DETECTOR_PARAMS(HPD_DEFAULT)
#undef HPD_DEFAULT
  return out;
}

// Every match of `pattern` (group 1 the name, group 2 the value) in `text`.
std::map<std::string, std::string> scan(const std::string& text, const std::string& pattern)
{
  std::map<std::string, std::string> out;
  const std::regex re(pattern);
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
    out[(*it)[1]] = (*it)[2];
  return out;
}

void expectSameDefaults(const std::map<std::string, std::string>& stated, const char* where,
                        const std::set<std::string>& may_be_missing = {})
{
  for (const auto& [name, value] : coreDefaults())
  {
    const auto it = stated.find(name);
    if (it == stated.end())
    {
      EXPECT_TRUE(may_be_missing.count(name)) << name << " is missing from " << where;
      continue;
    }
    char* end = nullptr;
    const double number = std::strtod(it->second.c_str(), &end);
    EXPECT_TRUE(end != it->second.c_str()) << where << " states '" << it->second << "' for " << name;
    EXPECT_NEAR(number, value, 1e-9 * std::max(1.0, std::abs(value)))
        << where << " states " << it->second << " for " << name << ", the core's default is " << value;
  }
}
}  // namespace

TEST(ParameterTables, TheReconfigureConfigStatesTheCoresDefaults)
{
  // gen.add("name", type_t, level, "description", default, ...
  const auto stated = scan(readFile("cfg/HoughPlaneDetector.cfg"),
                           R"re(gen\.add\("(\w+)",\s*\w+,\s*\d+,\s*"[^"]*",\s*([-+0-9.eE]+))re");
  ASSERT_FALSE(stated.empty());
  expectSameDefaults(stated, "cfg/HoughPlaneDetector.cfg");
}

TEST(ParameterTables, TheLaunchParametersStateTheCoresDefaults)
{
  // name: value; angle_step and d_step act only with resolution 0 and are left out.
  const auto stated = scan(readFile("launch/detector_params.yaml"), R"re((?:^|\n)(\w+):\s*([-+0-9.eE]+))re");
  ASSERT_FALSE(stated.empty());
  expectSameDefaults(stated, "launch/detector_params.yaml", {"angle_step", "d_step"});
}

TEST(ParameterTables, TheReadmeTableStatesTheCoresDefaults)
{
  // | name | type | default | meaning |
  const auto stated = scan(readFile("README.md"), R"re(\n\| (\w+) \| (?:int|double) \| ([-+0-9.eE]+) \|)re");
  ASSERT_FALSE(stated.empty());
  expectSameDefaults(stated, "README.md's parameter table");
}
