// fvp's core types from Python: the registries (planners, map engines, backends), the
// rectified stereo pair's intrinsics and a stereo frame from numpy arrays.
#include <pybind11/stl.h>

#include <stdexcept>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/core/input_checks.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/planner/planner_registry.h"

namespace fvp::python {

std::unique_ptr<accel::Backend> backendFor(const std::string& name, const std::string& engine) {
  if (name == "none") {
    if (host::map::mapEngineNeedsBackend(engine))
      throw std::invalid_argument("backend 'none': map engine '" + engine +
                                  "' needs a compute backend");
    return nullptr;
  }
  const auto choice = accel::parseBackendChoice(name);
  if (!choice)
    throw std::invalid_argument("backend: expected one of none, " + accel::backendChoiceNames() +
                                ", got '" + name + "'");
  return host::map::createBackendFor(engine, *choice);
}

void bindCore(py::module_& m) {
  m.def(
      "planners", [] { return host::planner::PlannerRegistry::instance().names(); },
      "The registered viewpoint planners' names.");
  m.def(
      "map_engines", [] { return host::map::MapEngineRegistry::instance().names(); },
      "The registered map engines' names.");
  m.def(
      "backends",
      [] {
        py::dict out;
        for (const auto& info : accel::probeBackends())
          out[py::str(std::string(accel::toString(info.kind)))] =
              info.available ? std::string("available") : info.reason;
        return out;
      },
      "Every compute backend built in: 'available', or why it cannot run here.");

  py::class_<host::StereoIntrinsics>(m, "StereoIntrinsics",
                                     "Rectified stereo pair: pixels, focal lengths, baseline.")
      .def(py::init([](int width_px, int height_px, double fx_px, double fy_px, double cx_px,
                       double cy_px, double baseline_m) {
             host::StereoIntrinsics k;
             k.width_px = width_px;
             k.height_px = height_px;
             k.fx_px = fx_px;
             k.fy_px = fy_px;
             k.cx_px = cx_px;
             k.cy_px = cy_px;
             k.baseline_m = baseline_m;
             host::checkIntrinsics(k, "StereoIntrinsics");
             return k;
           }),
           py::kw_only(), py::arg("width_px"), py::arg("height_px"), py::arg("fx_px"),
           py::arg("fy_px"), py::arg("cx_px"), py::arg("cy_px"), py::arg("baseline_m"))
      .def_readonly("width_px", &host::StereoIntrinsics::width_px)
      .def_readonly("height_px", &host::StereoIntrinsics::height_px)
      .def_readonly("fx_px", &host::StereoIntrinsics::fx_px)
      .def_readonly("fy_px", &host::StereoIntrinsics::fy_px)
      .def_readonly("cx_px", &host::StereoIntrinsics::cx_px)
      .def_readonly("cy_px", &host::StereoIntrinsics::cy_px)
      .def_readonly("baseline_m", &host::StereoIntrinsics::baseline_m);

  py::class_<host::StereoFrame>(m, "StereoFrame",
                                "One rectified stereo view with its pose; optionally the "
                                "robot's own fruitlet mask and disparity, used as given. A "
                                "uint16 fruitlet_mask is an instance segmentation (0 = "
                                "background, each id one fruitlet); any other is a binary "
                                "mask (nonzero = fruitlet).")
      .def(py::init([](const py::handle& left, const py::handle& right,
                       const host::StereoIntrinsics& intrinsics, const py::handle& T_world_camera,
                       const py::handle& fruitlet_mask, const py::handle& disparity_px) {
             host::StereoFrame f;
             f.left_bgr = bgrFromArray(left, "StereoFrame left");
             f.right_bgr = bgrFromArray(right, "StereoFrame right");
             f.intrinsics = intrinsics;
             f.T_world_camera = poseFromArray(T_world_camera, "StereoFrame T_world_camera");
             if (!fruitlet_mask.is_none())
               f.fruitlet_mask = maskFromArray(fruitlet_mask, "StereoFrame fruitlet_mask");
             if (!disparity_px.is_none())
               f.disparity_px = floatImageFromArray(disparity_px, "StereoFrame disparity_px");
             host::checkStereoFrame(f, "StereoFrame");
             return f;
           }),
           py::arg("left"), py::arg("right"), py::arg("intrinsics"), py::arg("T_world_camera"),
           py::arg("fruitlet_mask") = py::none(), py::arg("disparity_px") = py::none())
      .def_property_readonly("left",
                             [](const host::StereoFrame& f) { return imageToArray(f.left_bgr); })
      .def_property_readonly("right",
                             [](const host::StereoFrame& f) { return imageToArray(f.right_bgr); })
      .def_property_readonly(
          "fruitlet_mask", [](const host::StereoFrame& f) { return imageToArray(f.fruitlet_mask); })
      .def_property_readonly(
          "disparity_px", [](const host::StereoFrame& f) { return imageToArray(f.disparity_px); })
      .def_readonly("intrinsics", &host::StereoFrame::intrinsics)
      .def_property_readonly("T_world_camera", [](const host::StereoFrame& f) {
        return poseToArray(f.T_world_camera);
      });
}

}  // namespace fvp::python
