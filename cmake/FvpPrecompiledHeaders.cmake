# Precompiled headers: the third-party and standard headers nearly every source includes
# (json ~2 s, Eigen ~1.5 s, OpenCV ~1.3 s, GoogleTest ~1.4 s, CLI11 ~5 s, pybind11 ~5 s of
# parsing each, measured with g++ 12) are parsed once per target instead of once per source.
# Build time only: nothing installed depends on them. Sources still include what they use:
# -DFVP_PRECOMPILE_HEADERS=OFF builds without them, as the fuzz build (scripts/fuzz) does.
# No project header is precompiled, so editing one rebuilds only its includers.
option(FVP_PRECOMPILE_HEADERS "Precompile the common third-party headers" ON)

set(FVP_PCH_STD <algorithm> <array> <chrono> <cmath> <cstdint> <filesystem> <fstream>
    <functional> <map> <memory> <optional> <random> <set> <sstream> <stdexcept> <string>
    <unordered_map> <utility> <vector>)
set(FVP_PCH_EIGEN <Eigen/Core> <Eigen/Geometry>)
set(FVP_PCH_JSON <nlohmann/json.hpp>)
set(FVP_PCH_OPENCV <opencv2/core.hpp> <opencv2/imgproc.hpp>)

# fvp_precompile_headers(<target> [JSON] [OPENCV] [HEADERS <extra>...]): the standard library
# and Eigen, plus json, OpenCV and any extra headers the target's sources use. Each target
# gets its own precompiled header: targets differ in flags (-fopenmp changes what Eigen
# declares), and GCC only takes a precompiled header built with the same ones.
function(fvp_precompile_headers target)
  if(NOT FVP_PRECOMPILE_HEADERS)
    return()
  endif()
  cmake_parse_arguments(ARG "JSON;OPENCV" "" "HEADERS" ${ARGN})
  set(headers ${FVP_PCH_STD} ${FVP_PCH_EIGEN})
  if(ARG_JSON)
    list(APPEND headers ${FVP_PCH_JSON})
  endif()
  if(ARG_OPENCV)
    list(APPEND headers ${FVP_PCH_OPENCV})
  endif()
  target_precompile_headers(${target} PRIVATE ${headers} ${ARG_HEADERS})
endfunction()
