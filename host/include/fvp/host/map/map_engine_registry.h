// Map engines by name: `--engine`, MappingSession, the planners' defaults and the Python
// module create engines only through here. grid (dense bricks on a compute backend) and
// octomap (OctoMap octrees on the host) are built in; a program can add its own.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fvp/accel/backend_choice.h"
#include "fvp/host/core/cluster_region.h"
#include "fvp/host/core/named_registry.h"
#include "fvp/host/map/map_config.h"

namespace fvp::accel {
class Backend;
}

namespace fvp::host::map {

class MapEngine;

struct MapEngineEntry {
  std::string name;            ///< what --engine takes, e.g. "grid"
  bool needs_backend = false;  ///< runs its kernels on a compute backend
  /// backend is non-null when needs_backend. Throws std::invalid_argument for a bad config.
  std::function<std::unique_ptr<MapEngine>(const MapConfig& config, const ClusterRegion& region,
                                           accel::Backend* backend)>
      create;
};

class MapEngineRegistry : public NamedRegistry<MapEngineEntry> {
 public:
  /// The process's registry, holding the built-in entries.
  static MapEngineRegistry& instance();

  /// Also throws std::invalid_argument when create is missing.
  void add(MapEngineEntry entry);

 private:
  MapEngineRegistry();
};

/// Whether the named engine needs a compute backend (throws for an unknown name).
bool mapEngineNeedsBackend(std::string_view engine);
/// The backend a run on this engine uses: the chosen one when the engine needs one or a
/// backend is named (not kAuto), else none (null).
std::unique_ptr<accel::Backend> createBackendFor(std::string_view engine,
                                                 accel::BackendChoice backend);

}  // namespace fvp::host::map
