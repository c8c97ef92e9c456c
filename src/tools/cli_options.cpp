#include "hough_plane_detector/tools/cli_options.h"

#include <cmath>
#include <cstdio>
#include <sstream>

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

std::string escapeJson(const std::string& s)
{
  std::string out;
  for (char c : s)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += c;
    }
    else if (static_cast<unsigned char>(c) < 0x20)
    {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
    }
    else
    {
      out += c;
    }
  }
  return out;
}
}  // namespace

bool setDetectorParam(DetectorParams& params, const std::string& name, const std::string& value, std::string* error)
{
  for (const ParamEntry& entry : paramTable())
  {
    if (name != entry.name) continue;
    std::istringstream in(value);
    if (entry.int_member)
    {
      int v;
      if (!(in >> v) || !in.eof())
      {
        if (error) *error = "parameter " + name + " needs an integer, got '" + value + "'";
        return false;
      }
      params.*entry.int_member = v;
    }
    else
    {
      double v;
      if (!(in >> v) || !in.eof() || !std::isfinite(v))
      {
        if (error) *error = "parameter " + name + " needs a finite number, got '" + value + "'";
        return false;
      }
      params.*entry.double_member = v;
    }
    return true;
  }
  if (error) *error = "unknown parameter '" + name + "'";
  return false;
}

std::vector<std::string> detectorParamHelp()
{
  const DetectorParams defaults;
  std::vector<std::string> lines;
  for (const ParamEntry& entry : paramTable())
  {
    std::ostringstream line;
    line << "--" << entry.name << " ("
         << (entry.int_member ? "int, default " + std::to_string(defaults.*entry.int_member)
                              : "double, default " + number(defaults.*entry.double_member))
         << ")";
    lines.push_back(line.str());
  }
  return lines;
}

std::string frameToJson(int frame, double stamp, const std::string& frame_id, double ms,
                        const std::vector<DetectedPlane>& planes)
{
  std::ostringstream out;
  out << "{\"frame\": " << frame << ", \"stamp\": " << number(stamp) << ", \"frame_id\": \"" << escapeJson(frame_id)
      << "\", \"ms\": " << number(ms) << ", \"planes\": [";
  for (size_t i = 0; i < planes.size(); ++i)
  {
    const DetectedPlane& p = planes[i];
    out << (i ? ", " : "") << "{\"id\": " << p.id << ", \"normal\": [" << number(p.normal.x()) << ", "
        << number(p.normal.y()) << ", " << number(p.normal.z()) << "], \"d\": " << number(p.d)
        << ", \"strength\": " << number(p.strength) << ", \"support\": " << p.support << "}";
  }
  out << "]}";
  return out.str();
}

}  // namespace hough_plane_detector
