// The library's setup from Python (host/nbv/nbv_setup.h): one cluster or a tour over several,
// with the budget or the automatic stop, through a user's camera, arm and clock.
#include <pybind11/stl.h>

#include <optional>

#include "bindings.h"
#include "conversions.h"
#include "fvp/host/eval/sizing_score.h"
#include "fvp/host/nbv/nbv_setup.h"
#include "fvp/host/nbv/run_fields.h"
#include "run_keywords.h"

namespace fvp::python {
namespace {

using host::nbv::ClusterRun;
using host::nbv::ClusterTarget;
using host::nbv::ClusterVisit;
using host::nbv::NbvSetup;
using host::nbv::NbvSetupOptions;

py::dict snapshotToDict(const host::nbv::SizingSnapshot& s) {
  py::list fruitlets;
  for (const auto& f : s.fruitlets) {
    py::dict d;
    d["center_m"] = vectorToArray(f.center_m + s.world_shift_m);
    d["size_mm"] = f.size_mm;
    d["well_seen_images"] = f.well_seen_images;
    d["view_span_deg"] = f.view_span_deg;
    fruitlets.append(d);
  }
  py::dict d;
  d["view"] = s.view;
  d["now_s"] = s.now_s;
  d["sized_any_image"] = s.sized_any_image;
  d["fruitlets"] = fruitlets;
  return d;
}

py::dict clusterRunToDict(const ClusterRun& run) {
  py::dict d = nbvResultToDict(run.run);
  d["start_s"] = run.start_s;
  d["sizing"] = jsonToPython(host::eval::sizingDetails(run.sizing));
  d["sizing_wall_s"] = run.sizing_wall_s;
  d["sizing_during_loop_s"] = run.sizing_during_loop_s;
  py::list history;
  for (const auto& s : run.size_history) history.append(snapshotToDict(s));
  d["size_history"] = history;
  d["sizing_views"] = run.sizing_views;
  d["sizing_targets_dropped"] = run.sizing_targets_dropped;
  d["approaches_without_tag"] = run.approaches_without_tag;
  return d;
}

py::dict visitToDict(const ClusterVisit& v) {
  py::dict d;
  d["index"] = v.index;
  d["status"] = host::nbv::toString(v.status);
  d["arrival_s"] = v.arrival_s;
  d["loop_start_s"] = v.loop_start_s;
  d["approach_distance_m"] = v.approach_distance_m ? py::cast(*v.approach_distance_m) : py::none();
  d["approach_yaw_deg"] = v.approach_yaw_deg ? py::cast(*v.approach_yaw_deg) : py::none();
  d["move_status"] = v.move_status;
  d["run"] = v.run ? py::object(clusterRunToDict(*v.run)) : py::none();
  return d;
}

/// The loop's hooks and the tour's: on_cluster_start(index), on_cluster_done(dict),
/// on_cluster_skipped(dict), each optional.
class PyTourObserver : public host::nbv::TourObserver {
 public:
  explicit PyTourObserver(py::object target) : loop_(target), target_(std::move(target)) {}
  void onView(const host::nbv::ViewEvent& e) override { loop_.onView(e); }
  void onPlan(const host::nbv::PlanEvent& e) override { loop_.onPlan(e); }
  void onDroppedFrame(const std::string& detail) override { loop_.onDroppedFrame(detail); }
  void onClusterStart(std::size_t index, const ClusterTarget&) override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(target_, "on_cluster_start")) target_.attr("on_cluster_start")(index);
  }
  void onClusterDone(const ClusterVisit& visit, const host::nbv::ClusterWork&) override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(target_, "on_cluster_done"))
      target_.attr("on_cluster_done")(visitToDict(visit));
  }
  void onClusterSkipped(const ClusterVisit& visit) override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(target_, "on_cluster_skipped"))
      target_.attr("on_cluster_skipped")(visitToDict(visit));
  }

 private:
  PyObserver loop_;
  py::object target_;
};

NbvSetupOptions setupOptions(const py::kwargs& kw) {
  NbvSetupOptions o;
  RunKeywords keywords(kw, "NbvSetup");
  host::nbv::visitSetupFields(o, keywords);
  if (auto v = keywords.takeObject("perception")) o.perception = v->cast<host::PerceptionConfig>();
  keywords.finish();
  return o;
}

/// The caller's clock, or the wall clock from now.
struct ClockChoice {
  explicit ClockChoice(host::nbv::LoopClock* given) : clock(given ? *given : steady) {}
  host::nbv::SteadyLoopClock steady;
  host::nbv::LoopClock& clock;
};

}  // namespace

void bindSetup(py::module_& m) {
  py::class_<host::nbv::LoopClock>(m, "LoopClock",
                                   "The loop's clock (a robot's is the wall clock; the "
                                   "simulator's charges its modelled times).")
      .def("now_s", &host::nbv::LoopClock::now_s);

  py::class_<ClusterTarget>(m, "ClusterTarget",
                            "A cluster to visit: its tag or region, and "
                            "where to first look at it from.")
      .def(py::init([](const py::object& T, const py::object& center, std::optional<int> tag_id,
                       const py::object& region_center) {
             ClusterTarget t;
             t.T_world_start_camera = poseFromArray(T, "ClusterTarget T_world_start_camera");
             t.center_m = vectorFromArray(center, "ClusterTarget center_m");
             t.tag_id = tag_id;
             if (!region_center.is_none())
               t.region_center_m = vectorFromArray(region_center, "ClusterTarget region_center_m");
             return t;
           }),
           py::kw_only(), py::arg("T_world_start_camera"), py::arg("center_m"),
           py::arg("tag_id") = py::none(), py::arg("region_center_m") = py::none())
      .def_readonly("tag_id", &ClusterTarget::tag_id)
      .def_property_readonly(
          "T_world_start_camera",
          [](const ClusterTarget& t) { return poseToArray(t.T_world_start_camera); })
      .def_property_readonly("center_m",
                             [](const ClusterTarget& t) { return vectorToArray(t.center_m); });

  static const std::string doc =
      "The one place a run is assembled (host/nbv/nbv_setup.h). Keywords:\n" +
      keywordDoc(
          NbvSetupOptions{},
          [](const NbvSetupOptions& o, auto&& visit) { host::nbv::visitSetupFields(o, visit); },
          [](const auto& value) { return host::nbv::settingJson(value); }) +
      "  perception (default: the built-in): fvp.PerceptionConfig for every cluster\n";
  py::class_<NbvSetup>(m, "NbvSetup", doc.c_str())
      .def(py::init(
          [](const py::kwargs& kw) { return std::make_unique<NbvSetup>(setupOptions(kw)); }))
      .def_property_readonly("engine", &NbvSetup::engine)
      .def(
          "run_cluster",
          [](NbvSetup& setup, host::nbv::Camera& camera, host::nbv::Arm& arm,
             const ClusterTarget& target, host::nbv::LoopClock* clock, const py::object& observer) {
            std::optional<PyObserver> hooks;
            if (!observer.is_none()) hooks.emplace(observer);
            ClusterRun run;
            {
              py::gil_scoped_release release;
              ClockChoice chosen(clock);
              const auto work = setup.makeWork(target);
              run = setup.runCluster({camera, arm, chosen.clock}, *work, hooks ? &*hooks : nullptr);
            }
            return clusterRunToDict(run);
          },
          py::kw_only(), py::arg("camera"), py::arg("arm"), py::arg("target"),
          py::arg("clock") = nullptr, py::arg("observer") = py::none(),
          "The loop on one cluster from where the arm is, until the stop; then its sizing.")
      .def(
          "run_tour",
          [](NbvSetup& setup, host::nbv::Camera& camera, host::nbv::Arm& arm,
             const std::vector<ClusterTarget>& targets, host::nbv::LoopClock* clock,
             const py::object& observer) {
            std::optional<PyTourObserver> hooks;
            if (!observer.is_none()) hooks.emplace(observer);
            host::nbv::TourResult tour;
            {
              py::gil_scoped_release release;
              ClockChoice chosen(clock);
              tour = setup.runTour({camera, arm, chosen.clock}, targets, hooks ? &*hooks : nullptr);
            }
            py::list visits;
            for (const auto& v : tour.visits) visits.append(visitToDict(v));
            py::dict d;
            d["visits"] = visits;
            d["transit_s"] = tour.transit_s;
            d["transit_motion_s"] = tour.transit_motion_s;
            d["transit_motion"] = tour.transit_motion;
            return d;
          },
          py::kw_only(), py::arg("camera"), py::arg("arm"), py::arg("targets"),
          py::arg("clock") = nullptr, py::arg("observer") = py::none(),
          "The clusters one after another (nearest start view next, approach views, skips "
          "counted); returns visits (in visit order), transit_s (of it transit_motion_s in "
          "motion), transit_motion.");
}

}  // namespace fvp::python
