// Planners and map engines by name: the built-ins, the messages for unknown names, and an
// entry a program adds being what createPlanner / createMapEngine then make.
#include <gtest/gtest.h>

#include "fvp/host/map/map_engine.h"
#include "fvp/host/map/map_engine_registry.h"
#include "fvp/host/map/octomap_map_engine.h"
#include "fvp/host/planner/planner_registry.h"

namespace fvp::host {
namespace {

class StayPlanner : public planner::ViewPlanner {
 public:
  std::string_view name() const override { return "stay"; }
  std::optional<planner::Ranking> rank(map::MapEngine&, const Eigen::Isometry3d&,
                                       const planner::ReachabilityFn&, std::size_t,
                                       planner::PlanStep&) override {
    return std::nullopt;
  }
  std::string configJson() const override { return "{}"; }
};

TEST(PlannerRegistry, BuiltInsAndTheirDefaults) {
  auto& registry = planner::PlannerRegistry::instance();
  ASSERT_GE(registry.names().size(), 2u);
  EXPECT_EQ(registry.names()[0], "fvp");
  EXPECT_EQ(registry.names()[1], "rvp");
  EXPECT_EQ(registry.at("fvp").default_engine, "grid");
  EXPECT_EQ(registry.at("rvp").default_engine, "octomap");
  EXPECT_EQ(planner::createPlanner("rvp", "", 1, nullptr)->name(), "rvp");
  EXPECT_EQ(planner::plannerMapConfig("rvp", "octomap").fine_map_extent,
            map::FineMapExtent::kObservationBox);
  EXPECT_EQ(planner::plannerMapConfig("rvp", "grid").fine_map_extent,
            map::MapConfig{}.fine_map_extent);
  EXPECT_EQ(planner::plannerMapConfig("fvp", "octomap").fine_map_extent,
            map::MapConfig{}.fine_map_extent);
}

TEST(PlannerRegistry, UnknownNamesListTheKnownOnes) {
  try {
    planner::createPlanner("nbvp", "", 1, nullptr);
    FAIL() << "an unknown planner must throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown planner 'nbvp' (known: fvp, rvp"),
              std::string::npos)
        << e.what();
  }
}

TEST(PlannerRegistry, AProgramsOwnPlannerIsCreatedByName) {
  auto& registry = planner::PlannerRegistry::instance();
  if (!registry.contains("stay"))
    registry.add({"stay",
                  "",
                  "octomap",
                  [](const std::filesystem::path&, std::uint64_t, accel::Backend*) {
                    return std::unique_ptr<planner::ViewPlanner>(std::make_unique<StayPlanner>());
                  },
                  {}});
  EXPECT_EQ(planner::createPlanner("stay", "", 1, nullptr)->name(), "stay");
  EXPECT_EQ(registry.at("stay").label, "stay");  // defaults to the name
  EXPECT_THROW(registry.add({"stay", "", "", registry.at("stay").create, {}}),
               std::invalid_argument);
  EXPECT_THROW(registry.add({"nothing", "", "", {}, {}}), std::invalid_argument);
}

TEST(MapEngineRegistry, BuiltInsNeedsAndUnknownNames) {
  EXPECT_TRUE(map::mapEngineNeedsBackend("grid"));
  EXPECT_FALSE(map::mapEngineNeedsBackend("octomap"));
  EXPECT_THROW(map::checkMapEngineChoice("grid", nullptr), std::invalid_argument);
  try {
    map::mapEngineNeedsBackend("voxblox");
    FAIL() << "an unknown engine must throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown map engine 'voxblox' (known: grid, octomap"),
              std::string::npos)
        << e.what();
  }
}

TEST(MapEngineRegistry, AProgramsOwnEngineIsCreatedByName) {
  auto& registry = map::MapEngineRegistry::instance();
  // Static: the registry outlives the test.
  static int created = 0;
  const int before = created;
  if (!registry.contains("octomap-counted"))
    registry.add({"octomap-counted", false,
                  [](const map::MapConfig& config, const ClusterRegion& region, accel::Backend*) {
                    ++created;
                    return std::unique_ptr<map::MapEngine>(
                        std::make_unique<map::OctomapMapEngine>(config, region));
                  }});
  const ClusterRegion region(Eigen::Vector3d(0.0, 0.0, 1.0), 0.05);
  const auto engine = map::createMapEngine("octomap-counted", map::MapConfig{}, region, nullptr);
  EXPECT_EQ(engine->engineName(), "octomap");
  EXPECT_EQ(created, before + 1);
}

}  // namespace
}  // namespace fvp::host
