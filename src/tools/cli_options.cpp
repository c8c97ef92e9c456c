#include "hough_plane_detector/tools/cli_options.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "hough_plane_detector/core/sensor_model.h"

namespace hough_plane_detector
{

namespace
{
struct ParamEntry
{
  const char* name;
  int DetectorParams::*int_member;
  double DetectorParams::*double_member;
};

ParamEntry entry(const char* name, int DetectorParams::*member)
{
  return ParamEntry{name, member, nullptr};
}

ParamEntry entry(const char* name, double DetectorParams::*member)
{
  return ParamEntry{name, nullptr, member};
}

const std::vector<ParamEntry>& paramTable()
{
#define HPD_PARAM_ENTRY(type, name) entry(#name, &DetectorParams::name),
  static const std::vector<ParamEntry> table = {HOUGH_PLANE_DETECTOR_PARAMS(HPD_PARAM_ENTRY)};
#undef HPD_PARAM_ENTRY
  return table;
}

std::string number(double v)
{
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

}  // namespace

bool parseInteger(const std::string& text, int* out)
{
  std::istringstream in(text);
  int v;
  if (!(in >> v) || !in.eof()) return false;
  *out = v;
  return true;
}

bool parseFinite(const std::string& text, double* out)
{
  std::istringstream in(text);
  double v;
  if (!(in >> v) || !in.eof() || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool setDetectorParam(DetectorParams& params, const std::string& name, const std::string& value, std::string* error)
{
  for (const ParamEntry& entry : paramTable())
  {
    if (name != entry.name) continue;
    if (name == "sensor_model")  // by name as well as by number
    {
      if (!parseSensorModel(value, &params.sensor_model))
      {
        if (error) *error = "parameter sensor_model needs kinect_v1, xtion, realsense_d400 or tof (or 0-3), got '" + value + "'";
        return false;
      }
      return true;
    }
    if (entry.int_member ? !parseInteger(value, &(params.*entry.int_member))
                         : !parseFinite(value, &(params.*entry.double_member)))
    {
      if (error)
        *error = "parameter " + name + (entry.int_member ? " needs an integer" : " needs a finite number") + ", got '" +
                 value + "'";
      return false;
    }
    return true;
  }
  if (error) *error = "unknown parameter '" + name + "'";
  return false;
}

void addDetectorParamOptions(DetectorParams& params, boost::program_options::options_description& visible,
                             boost::program_options::options_description& hidden)
{
  namespace po = boost::program_options;
  const DetectorParams defaults;
  for (const ParamEntry& entry : paramTable())
  {
    const std::string name = entry.name;
    const std::string help = entry.int_member ? "int, default " + std::to_string(defaults.*entry.int_member)
                                              : "double, default " + number(defaults.*entry.double_member);
    auto apply = [&params, name](const std::string& value) {
      std::string error;
      if (!setDetectorParam(params, name, value, &error)) throw po::error(error);
    };
    visible.add_options()(name.c_str(), po::value<std::string>()->value_name("VALUE")->notifier(apply), help.c_str());
    std::string dashed = name;
    for (char& c : dashed)
      if (c == '_') c = '-';
    if (dashed != name) hidden.add_options()(dashed.c_str(), po::value<std::string>()->notifier(apply), "");
  }
}

void assumeCameraFrame(const boost::program_options::variables_map& values, DetectorParams& params)
{
  if (!values.count("world_z_up") && !values.count("world-z-up")) params.world_z_up = 0;
}

bool parseCommandLine(int argc, char** argv, const boost::program_options::options_description& options,
                      const boost::program_options::positional_options_description& positional,
                      boost::program_options::variables_map& values, std::string* error)
{
  namespace po = boost::program_options;
  try
  {
    // Whole option names only: a prefix that happens to match one parameter is a typo, not a choice.
    const int style = po::command_line_style::default_style & ~po::command_line_style::allow_guessing;
    po::store(po::command_line_parser(argc, argv).options(options).positional(positional).style(style).run(), values);
    po::notify(values);
  }
  catch (const po::error& e)
  {
    if (error) *error = e.what();
    return false;
  }
  return true;
}

namespace
{
nlohmann::ordered_json pointsToJson(const std::vector<Eigen::Vector3d>& points)
{
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const Eigen::Vector3d& p : points) out.push_back({p.x(), p.y(), p.z()});
  return out;
}
}  // namespace

std::string frameToJson(int frame, double stamp, const std::string& frame_id, double ms,
                        const std::vector<DetectedPlane>& planes, const std::vector<std::vector<PlaneOutline>>& outlines)
{
  // nlohmann::json prints doubles so that they read back exactly (a 2025 stamp keeps its
  // microseconds) and escapes strings; a non-finite number becomes null.
  nlohmann::ordered_json out;
  out["frame"] = frame;
  out["stamp"] = stamp;
  out["frame_id"] = frame_id;
  out["ms"] = ms;
  out["planes"] = nlohmann::ordered_json::array();
  for (const DetectedPlane& p : planes)
  {
    nlohmann::ordered_json plane;
    plane["id"] = p.id;
    plane["normal"] = {p.normal.x(), p.normal.y(), p.normal.z()};
    plane["d"] = p.d;
    plane["strength"] = p.strength;
    plane["support"] = p.support;
    plane["confirmations"] = p.confirmations;
    plane["contradictions"] = p.contradictions;
    const size_t index = out["planes"].size();
    if (index < outlines.size())
    {
      // One object per connected region: its area (m^2, holes excluded), outline and holes.
      plane["outlines"] = nlohmann::ordered_json::array();
      for (const PlaneOutline& region : outlines[index])
      {
        nlohmann::ordered_json shape;
        shape["area"] = region.area;
        shape["boundary"] = pointsToJson(region.boundary);
        shape["holes"] = nlohmann::ordered_json::array();
        for (const auto& hole : region.holes) shape["holes"].push_back(pointsToJson(hole));
        plane["outlines"].push_back(shape);
      }
    }
    out["planes"].push_back(plane);
  }
  return out.dump();
}

}  // namespace hough_plane_detector
