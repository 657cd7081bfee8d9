#include "conversions.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "fvp/host/core/input_checks.h"

namespace fvp::python {
namespace {

template <typename T>
py::array_t<T, py::array::c_style | py::array::forcecast> asArray(const py::handle& object,
                                                                  const std::string& what) {
  if (object.is_none()) throw std::invalid_argument(what + ": expected an array, got None");
  auto array = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!array) throw std::invalid_argument(what + ": expected a numeric array");
  return array;
}

/// Image data must already have one of the numpy kinds given ('u' unsigned, 'i' signed,
/// 'b' bool, 'f' float; itemsize 1 when only_bytes): a float image in 0..1 or a uint16 one
/// would otherwise be cast silently into nonsense.
void requireKind(const py::handle& object, const std::string& kinds, bool only_bytes,
                 const std::string& what, const std::string& expected) {
  const py::array array = py::array::ensure(object);
  if (!array) throw std::invalid_argument(what + ": expected " + expected);
  const py::dtype dtype = array.dtype();
  if (kinds.find(dtype.kind()) == std::string::npos || (only_bytes && dtype.itemsize() != 1))
    throw std::invalid_argument(what + ": expected " + expected + ", got dtype " +
                                std::string(py::str(static_cast<const py::handle&>(dtype))));
}

/// Wildcard sides (-1) must be 1 .. INT_MAX (an OpenCV image side).
void requireShape(const py::array& array, std::vector<py::ssize_t> shape, const std::string& what) {
  bool ok = array.ndim() == py::ssize_t(shape.size());
  for (std::size_t i = 0; ok && i < shape.size(); ++i) {
    const py::ssize_t side = array.shape(py::ssize_t(i));
    ok = shape[i] < 0 ? side >= 1 && side <= std::numeric_limits<int>::max() : side == shape[i];
  }
  if (ok) return;
  std::string expected = "(", got = "(";
  for (std::size_t i = 0; i < shape.size(); ++i)
    expected +=
        (i ? ", " : "") + (shape[i] < 0 ? std::string(1, "HW"[i % 2]) : std::to_string(shape[i]));
  for (py::ssize_t i = 0; i < array.ndim(); ++i)
    got += (i ? ", " : "") + std::to_string(array.shape(i));
  throw std::invalid_argument(what + ": expected shape " + expected + "), got " + got + ")");
}

}  // namespace

Eigen::Isometry3d poseFromArray(const py::handle& object, const std::string& what) {
  const auto array = asArray<double>(object, what);
  requireShape(array, {4, 4}, what);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = array.at(r, c);
  if (!(m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)) && m.row(3).allFinite()))
    throw std::invalid_argument(what + ": expected a 4x4 rigid transform, last row 0 0 0 1");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = m;
  host::checkPose(T, "python", what);
  return T;
}

py::array_t<double> poseToArray(const Eigen::Isometry3d& T) {
  py::array_t<double> out({4, 4});
  auto view = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) view(r, c) = T.matrix()(r, c);
  return out;
}

Eigen::Vector3d vectorFromArray(const py::handle& object, const std::string& what) {
  const auto array = asArray<double>(object, what);
  requireShape(array, {3}, what);
  const Eigen::Vector3d v(array.at(0), array.at(1), array.at(2));
  if (!v.allFinite()) throw std::invalid_argument(what + ": expected finite numbers");
  return v;
}

py::array_t<double> vectorToArray(const Eigen::Vector3d& v) {
  py::array_t<double> out(3);
  std::memcpy(out.mutable_data(), v.data(), 3 * sizeof(double));
  return out;
}

cv::Mat bgrFromArray(const py::handle& object, const std::string& what) {
  if (!object.is_none()) requireKind(object, "u", true, what, "a uint8 BGR image");
  const auto array = asArray<std::uint8_t>(object, what);
  requireShape(array, {-1, -1, 3}, what);
  cv::Mat image(int(array.shape(0)), int(array.shape(1)), CV_8UC3);
  std::memcpy(image.data, array.data(), image.total() * image.elemSize());
  return image;
}

cv::Mat maskFromArray(const py::handle& object, const std::string& what) {
  if (!object.is_none()) requireKind(object, "uib", false, what, "an integer or bool mask");
  // uint16: an instance segmentation, kept as its ids (StereoFrame::fruitlet_mask).
  if (py::isinstance<py::array_t<std::uint16_t>>(object)) {
    const auto ids = asArray<std::uint16_t>(object, what);
    requireShape(ids, {-1, -1}, what);
    cv::Mat instances(int(ids.shape(0)), int(ids.shape(1)), CV_16U);
    std::memcpy(instances.data, ids.data(), instances.total() * sizeof(std::uint16_t));
    return instances;
  }
  const auto array = asArray<std::int64_t>(object, what);
  requireShape(array, {-1, -1}, what);
  cv::Mat mask(int(array.shape(0)), int(array.shape(1)), CV_8U);
  const std::int64_t* in = array.data();
  for (std::size_t i = 0; i < mask.total(); ++i) mask.data[i] = in[i] != 0 ? 255 : 0;
  return mask;
}

cv::Mat floatImageFromArray(const py::handle& object, const std::string& what) {
  if (!object.is_none()) requireKind(object, "fui", false, what, "a disparity image (numbers)");
  const auto array = asArray<float>(object, what);
  requireShape(array, {-1, -1}, what);
  cv::Mat image(int(array.shape(0)), int(array.shape(1)), CV_32F);
  std::memcpy(image.data, array.data(), image.total() * sizeof(float));
  return image;
}

py::object imageToArray(const cv::Mat& image) {
  if (image.empty()) return py::none();
  const cv::Mat dense = image.isContinuous() ? image : image.clone();
  std::vector<py::ssize_t> shape{dense.rows, dense.cols};
  if (dense.channels() > 1) shape.push_back(dense.channels());
  py::array out;
  switch (dense.depth()) {
    case CV_8U:
      out = py::array_t<std::uint8_t>(shape);
      break;
    case CV_16U:
      out = py::array_t<std::uint16_t>(shape);
      break;
    case CV_32F:
      out = py::array_t<float>(shape);
      break;
    case CV_32S:
      out = py::array_t<std::int32_t>(shape);
      break;
    default:
      throw std::logic_error("imageToArray: unsupported image type");
  }
  std::memcpy(out.mutable_data(), dense.data, dense.total() * dense.elemSize());
  return out;
}

py::array_t<float> pointsToArray(const std::vector<Eigen::Vector3f>& points) {
  py::array_t<float> out({py::ssize_t(points.size()), py::ssize_t(3)});
  auto view = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) view(py::ssize_t(i), k) = points[i][k];
  return out;
}

py::object jsonToPython(const nlohmann::json& value) {
  // The json module parses what nlohmann writes exactly (NaN never occurs: results hold
  // null for undefined numbers).
  return py::module_::import("json").attr("loads")(value.dump());
}

bool boolFromPython(const py::handle& value, const std::string& what) {
  const std::string type = Py_TYPE(value.ptr())->tp_name;
  if (py::isinstance<py::bool_>(value) || type == "numpy.bool_") return value.cast<bool>();
  throw std::invalid_argument(what + ": expected a bool (True or False), got " +
                              (value.is_none() ? std::string("None") : type));
}

}  // namespace fvp::python
