// A small mapped scene shared by the planner tests: a 1.2 m observation box, a 4 cm Cluster
// Region with four synthetic fruitlets, seen from two views (octomap engine, no backend).
#pragma once

#include <memory>

#include "../map/synthetic_scan.h"
#include "fvp/host/map/map_engine.h"

namespace fvp::host::planner::testing {

inline map::MapConfig plannerTestConfig() {
  map::MapConfig c;
  c.observation_min_m = {-0.6, -0.6, 0.0};
  c.observation_max_m = {0.6, 0.6, 0.8};
  return c;
}

inline const ClusterRegion kPlannerTestRegion({0.0, 0.0, 0.3}, 0.04);

inline std::unique_ptr<map::MapEngine> mappedTestEngine() {
  auto e = map::createMapEngine("octomap", plannerTestConfig(), kPlannerTestRegion, nullptr);
  const auto world = map::testing::makeWorld(5, kPlannerTestRegion.center_m(), 4);
  e->integrate(map::testing::renderScan(world, {0.0, -0.3, 0.35}, 96, 72, 0.5, 5).clouds());
  e->integrate(map::testing::renderScan(world, {0.2, -0.25, 0.3}, 96, 72, 0.5, 6).clouds());
  return e;
}

}  // namespace fvp::host::planner::testing
