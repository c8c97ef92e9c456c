#include "hough_plane_detector/core/cloud_view.h"

#include <sstream>

namespace hough_plane_detector
{

namespace
{
size_t datatypeSize(uint8_t datatype)
{
  switch (static_cast<PointDatatype>(datatype))
  {
    case PointDatatype::kInt8:
    case PointDatatype::kUInt8: return 1;
    case PointDatatype::kInt16:
    case PointDatatype::kUInt16: return 2;
    case PointDatatype::kInt32:
    case PointDatatype::kUInt32:
    case PointDatatype::kFloat32: return 4;
    case PointDatatype::kFloat64: return 8;
  }
  return 0;
}

template <class T>
float readAs(const uint8_t* p)
{
  T value;
  std::memcpy(&value, p, sizeof(T));
  return static_cast<float>(value);
}

float readField(const uint8_t* p, uint8_t datatype)
{
  switch (static_cast<PointDatatype>(datatype))
  {
    case PointDatatype::kInt8: return readAs<int8_t>(p);
    case PointDatatype::kUInt8: return readAs<uint8_t>(p);
    case PointDatatype::kInt16: return readAs<int16_t>(p);
    case PointDatatype::kUInt16: return readAs<uint16_t>(p);
    case PointDatatype::kInt32: return readAs<int32_t>(p);
    case PointDatatype::kUInt32: return readAs<uint32_t>(p);
    case PointDatatype::kFloat32: return readAs<float>(p);
    case PointDatatype::kFloat64: return readAs<double>(p);
  }
  return 0.0f;
}

// What is wrong with the layout (empty: nothing); its x, y and z fields in `xyz`.
std::string layoutProblem(const PointBufferLayout& layout, const PointFieldLayout* xyz[3])
{
  std::ostringstream err;
  if (layout.width == 0 || layout.height == 0)
  {
    err << "cloud is empty (width " << layout.width << " x height " << layout.height << ")";
    return err.str();
  }
  if (layout.is_bigendian) return "cloud is big-endian; only little-endian clouds are supported";
  for (const auto& field : layout.fields)
    for (int axis = 0; axis < 3; ++axis)
      if (field.name == std::string(1, "xyz"[axis])) xyz[axis] = &field;
  std::string missing;
  for (int axis = 0; axis < 3; ++axis)
    if (!xyz[axis]) missing += std::string(missing.empty() ? "" : ", ") + "xyz"[axis];
  if (!missing.empty())
  {
    err << "cloud has no field " << missing << " (fields:";
    for (const auto& field : layout.fields) err << " " << field.name;
    err << ")";
    return err.str();
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    const size_t size = datatypeSize(xyz[axis]->datatype);
    if (size == 0)
    {
      err << "field " << xyz[axis]->name << " has unknown datatype " << int(xyz[axis]->datatype);
      return err.str();
    }
    if (xyz[axis]->offset + size > layout.point_step)
    {
      err << "field " << xyz[axis]->name << " (offset " << xyz[axis]->offset << ", " << size
          << " bytes) does not fit in point_step " << layout.point_step;
      return err.str();
    }
  }
  if (static_cast<uint64_t>(layout.point_step) * layout.width > layout.row_step)
  {
    err << "row_step " << layout.row_step << " is smaller than width " << layout.width << " x point_step "
        << layout.point_step;
    return err.str();
  }
  if (static_cast<uint64_t>(layout.row_step) * layout.height > layout.data_size)
  {
    err << "data holds " << layout.data_size << " bytes but row_step " << layout.row_step << " x height "
        << layout.height << " needs " << static_cast<uint64_t>(layout.row_step) * layout.height;
    return err.str();
  }
  return std::string();
}

// A view of a checked layout: float32 x/y/z in place, other datatypes (float64 from some
// drivers, integers in mm) converted once into `converted`.
void viewFields(const PointBufferLayout& layout, const PointFieldLayout* const xyz[3], CloudView& view,
                std::vector<float>& converted)
{
  view.width = static_cast<int>(layout.width);
  view.height = static_cast<int>(layout.height);
  bool all_float32 = true;
  for (int axis = 0; axis < 3; ++axis)
    all_float32 = all_float32 && xyz[axis]->datatype == static_cast<uint8_t>(PointDatatype::kFloat32);
  if (all_float32)
  {
    view.data = layout.data;
    view.point_step = layout.point_step;
    view.row_step = layout.row_step;
    view.x_offset = xyz[0]->offset;
    view.y_offset = xyz[1]->offset;
    view.z_offset = xyz[2]->offset;
    return;
  }
  converted.resize(static_cast<size_t>(layout.width) * layout.height * 3);
  for (uint32_t v = 0; v < layout.height; ++v)
    for (uint32_t u = 0; u < layout.width; ++u)
    {
      const uint8_t* p = layout.data + static_cast<size_t>(v) * layout.row_step + static_cast<size_t>(u) * layout.point_step;
      float* out = &converted[(static_cast<size_t>(v) * layout.width + u) * 3];
      for (int axis = 0; axis < 3; ++axis) out[axis] = readField(p + xyz[axis]->offset, xyz[axis]->datatype);
    }
  view.data = reinterpret_cast<const uint8_t*>(converted.data());
  view.point_step = 3 * sizeof(float);
  view.row_step = view.point_step * layout.width;
  view.x_offset = 0;
  view.y_offset = 4;
  view.z_offset = 8;
}
}  // namespace

bool makeCloudView(const PointBufferLayout& layout, CloudView& view, std::vector<float>& converted, std::string* error)
{
  const PointFieldLayout* xyz[3] = {nullptr, nullptr, nullptr};
  const std::string problem = layoutProblem(layout, xyz);
  if (!problem.empty())
  {
    if (error) *error = problem;
    return false;
  }
  viewFields(layout, xyz, view, converted);
  return true;
}

}  // namespace hough_plane_detector
