// Conversions between numpy arrays / Python objects and the library's types, with the
// library's own checks (a pose must be a rotation and a translation; images must match the
// intrinsics), so bad input from Python is an exception naming the argument.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace fvp::python {

namespace py = pybind11;

/// A (4, 4) array -> a checked pose (host::checkPose); `what` names the argument.
Eigen::Isometry3d poseFromArray(const py::handle& array, const std::string& what);

/// What a Python callback returned where a bool belongs: True/False or a numpy bool (what
/// an array comparison gives). Anything else, None included (a forgotten return), throws
/// std::invalid_argument (ValueError) "WHAT: expected a bool (True or False), got TYPE": one
/// rule for every callback, where pybind11 alone took None as False and refused a str with
/// "Unable to cast Python instance".
bool boolFromPython(const py::handle& value, const std::string& what);
/// A pose -> a new (4, 4) float64 array.
py::array_t<double> poseToArray(const Eigen::Isometry3d& T);
/// A (3,) array -> a finite vector.
Eigen::Vector3d vectorFromArray(const py::handle& array, const std::string& what);
py::array_t<double> vectorToArray(const Eigen::Vector3d& v);

/// A (H, W, 3) uint8 array (BGR, as OpenCV) -> a CV_8UC3 copy.
cv::Mat bgrFromArray(const py::handle& array, const std::string& what);
/// A (H, W) array of any integer or bool type -> CV_8U, 255 where nonzero (a binary mask
/// or instance ids: every nonzero id is a fruitlet pixel).
cv::Mat maskFromArray(const py::handle& array, const std::string& what);
/// A (H, W) array of numbers -> CV_32F (disparity in pixels, 0 invalid).
cv::Mat floatImageFromArray(const py::handle& array, const std::string& what);
/// Any CV_8UC3, CV_8U or CV_32F image -> a new numpy array (a copy); None when empty.
py::object imageToArray(const cv::Mat& image);

/// (N, 3) float32 / float64 arrays from points.
py::array_t<float> pointsToArray(const std::vector<Eigen::Vector3f>& points);

/// A JSON value as the equivalent Python object (dicts, lists, numbers, strings, None).
py::object jsonToPython(const nlohmann::json& value);

}  // namespace fvp::python
