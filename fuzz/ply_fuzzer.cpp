// readPlyPoints (host/src/perception/ply_io.cpp) on a file holding the input.
#include "fuzz_support.h"
#include "fvp/host/perception/ply_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fz = fvp::fuzz;
  const std::filesystem::path path = fz::scratchDir() / "cloud.ply";
  fz::writeFile(path, data, size);
  try {
    const std::vector<Eigen::Vector3f> points = fvp::host::readPlyPoints(path);
    // Every point has 12 bytes of x, y, z in the file.
    if (points.size() > size / 12) {
      std::fprintf(stderr, "fvp fuzz: %zu points from %zu bytes\n", points.size(), size);
      std::abort();
    }
  } catch (const std::exception&) {
    // Rejected: expected for most inputs.
  }
  return 0;
}
