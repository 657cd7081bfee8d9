// Every backend against the cpu reference. In CI (CI=true) or with
// FVP_REQUIRE_ALL_BACKENDS=1 an unavailable backend fails instead of skipping.
#include <gtest/gtest.h>

#include "backend_fixture.h"

#include <algorithm>
#include <cstdlib>
#include <random>
#include <string>

#include "fvp/accel/backend.h"
#include "fvp/accel/kernels.h"
#include "fvp/accel/ray_workload.h"
#include "fvp/accel/sequence.h"

namespace fvp::accel {
namespace {

// Sums run in the same order on every backend with contraction disabled, so they agree
// to the bit today; the tolerance allows a device that rounds float adds differently.
constexpr float kFieldSumRelativeTolerance = 1e-5f;

void expectSameWalks(const std::vector<RayResult>& got, const std::vector<RayResult>& want,
                     const std::string& context) {
  ASSERT_EQ(got.size(), want.size()) << context;
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].status, want[i].status) << context << ", ray " << i;
    ASSERT_EQ(got[i].steps, want[i].steps) << context << ", ray " << i;
    ASSERT_EQ(got[i].stop_voxel, want[i].stop_voxel) << context << ", ray " << i;
    ASSERT_NEAR(got[i].field_sum, want[i].field_sum,
                kFieldSumRelativeTolerance * std::max(1.0f, std::abs(want[i].field_sum)))
        << context << ", ray " << i;
  }
}

class BackendTest : public fvp::testing::BackendFixture {
 protected:
  void expectSameAsCpu(const DenseGrid& grid, const std::vector<Ray>& rays,
                       const std::string& context) {
    expectSameWalks(traverseOnBackend(*backend_, grid, rays), traverseOnBackend(*cpu_, grid, rays),
                    context);
  }
};

TEST_P(BackendTest, ReportsItsKindAndDevice) {
  EXPECT_EQ(backend_->kind(), GetParam());
  EXPECT_FALSE(backend_->deviceName().empty());
}

TEST_P(BackendTest, UploadDownloadRoundTripsAndChecksRanges) {
  std::vector<float> data(1000);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<float>(i) * 0.5f;
  auto buf = backend_->createBufferFrom(data);
  EXPECT_EQ(backend_->downloadAll<float>(*buf), data);
  const float patch[2] = {-1.0f, -2.0f};
  backend_->upload(*buf, patch, sizeof(patch), 10 * sizeof(float));
  float back[3];
  backend_->download(*buf, back, sizeof(back), 9 * sizeof(float));
  EXPECT_EQ(back[0], 4.5f);
  EXPECT_EQ(back[1], -1.0f);
  EXPECT_EQ(back[2], -2.0f);
  EXPECT_THROW(backend_->upload(*buf, patch, sizeof(patch), 999 * sizeof(float)),
               std::out_of_range);
  EXPECT_THROW(backend_->download(*buf, back, 4001), std::out_of_range);
}

// The planner's snapshot update: scattered ranges of a host image in one transfer, bytes
// outside them untouched, on the staging path (discrete GPUs) as on mapped memory.
TEST_P(BackendTest, UploadRangesCopiesOnlyTheRangesInOneTransfer) {
  const std::uint64_t seed = fvp::testing::freshSeed();
  SCOPED_TRACE(fvp::testing::replayHint(seed));
  std::mt19937_64 rng(seed);
  std::vector<std::uint8_t> device_was(100000), image(device_was.size());
  for (auto& b : device_was) b = static_cast<std::uint8_t>(rng());
  for (auto& b : image) b = static_cast<std::uint8_t>(rng());
  auto buf = backend_->createBufferFrom(device_was);
  std::vector<ByteRange> ranges;
  std::vector<std::uint8_t> want = device_was;
  for (int i = 0; i < 200; ++i) {
    const std::size_t offset = rng() % image.size();
    const std::size_t size = std::min<std::size_t>(rng() % 300, image.size() - offset);
    ranges.push_back({offset, size});  // overlapping and empty ones included
    std::copy_n(image.begin() + offset, size, want.begin() + offset);
  }
  backend_->resetTransfers();
  backend_->uploadRanges(*buf, image.data(), ranges);
  EXPECT_EQ(backend_->transfers().uploads, 1u);
  EXPECT_EQ(backend_->downloadAll<std::uint8_t>(*buf), want);
  const ByteRange outside[] = {{99990, 11}};
  EXPECT_THROW(backend_->uploadRanges(*buf, image.data(), outside), std::out_of_range);
}

TEST_P(BackendTest, TraverseRejectsShortBuffers) {
  const DenseGrid grid = makeCanopyGrid(16, 0.01f, 1);
  auto occupancy = backend_->createBufferFrom(grid.occupancy);
  auto field = backend_->createBuffer(8);  // far too small for 16^3 floats
  auto rays = backend_->createBuffer(sizeof(Ray));
  auto results = backend_->createBuffer(sizeof(RayResult));
  TraverseParams params{grid.params, kDefaultOccupiedThreshold, 1};
  EXPECT_THROW(backend_->run(kernels::rayTraverse(), params,
                             {rays.get(), occupancy.get(), field.get(), results.get()}),
               std::out_of_range);
}

TEST_P(BackendTest, DispatchChecksTheBindings) {
  const DenseGrid grid = makeCanopyGrid(16, 0.01f, 1);
  auto occupancy = backend_->createBufferFrom(grid.occupancy);
  auto rays = backend_->createBuffer(sizeof(Ray));
  auto results = backend_->createBuffer(sizeof(RayResult));
  TraverseParams params{grid.params, kDefaultOccupiedThreshold, 1};
  // One buffer short, and a used binding left null.
  EXPECT_THROW(
      backend_->run(kernels::rayTraverse(), params, {rays.get(), occupancy.get(), results.get()}),
      std::invalid_argument);
  EXPECT_THROW(backend_->run(kernels::rayTraverse(), params,
                             {rays.get(), occupancy.get(), nullptr, results.get()}),
               std::invalid_argument);
}

// The ray walk of `rays` over `grid` on the cpu reference.
std::vector<RayResult> cpuTraverse(const DenseGrid& grid, const std::vector<Ray>& rays) {
  auto cpu = createBackend(BackendKind::kCpu);
  return traverseOnBackend(*cpu, grid, rays);
}

// Two grids walked in one sequence: the second grid's uploads overwrite buffers the first
// dispatch read, and the second dispatch overwrites the results the first download read;
// each download sees the buffer as the operations before it left it. One wait in all.
TEST_P(BackendTest, SequenceRunsItsOperationsInOrderWithOneWait) {
  const DenseGrid a = makeCanopyGrid(32, 0.004f, 11), b = makeCanopyGrid(32, 0.004f, 12);
  const std::vector<Ray> rays = makeRandomRays(a.params, {3000, 0.5f}, 13);
  auto occupancy = backend_->createBuffer(a.occupancy.size() * sizeof(float));
  auto field = backend_->createBuffer(a.field.size() * sizeof(float));
  auto ray_buffer = backend_->createBufferFrom(rays);
  auto results = backend_->createBuffer(rays.size() * sizeof(RayResult));
  std::vector<RayResult> got_a(rays.size()), got_b(rays.size());
  Sequence seq(*backend_);
  for (const auto& [grid, got] : {std::pair{&a, &got_a}, std::pair{&b, &got_b}}) {
    const TraverseParams params{grid->params, kDefaultOccupiedThreshold, unsigned(rays.size())};
    seq.upload(*occupancy, grid->occupancy.data(), grid->occupancy.size() * sizeof(float))
        .upload(*field, grid->field.data(), grid->field.size() * sizeof(float))
        .run(kernels::rayTraverse(), params,
             {ray_buffer.get(), occupancy.get(), field.get(), results.get()})
        .download(*results, got->data(), got->size() * sizeof(RayResult));
  }
  EXPECT_EQ(seq.size(), 8u);
  backend_->resetTransfers();
  const std::uint64_t waits_before = backend_->deviceWaits();
  seq.eval();
  EXPECT_EQ(seq.size(), 0u);
  EXPECT_EQ(backend_->deviceWaits() - waits_before, GetParam() == BackendKind::kCpu ? 0u : 1u);
  EXPECT_EQ(backend_->transfers().uploads, 4u);
  EXPECT_EQ(backend_->transfers().downloads, 2u);
  expectSameWalks(got_a, cpuTraverse(a, rays), "grid a");
  expectSameWalks(got_b, cpuTraverse(b, rays), "grid b");
}

// More dispatches than one Vulkan submission holds (32): parts run in order, each
// download reading its own dispatch's results.
TEST_P(BackendTest, SequenceLongerThanOneSubmission) {
  const DenseGrid grid = makeCanopyGrid(32, 0.004f, 21);
  const std::vector<Ray> rays = makeRandomRays(grid.params, {400, 0.5f}, 22);
  auto occupancy = backend_->createBufferFrom(grid.occupancy);
  auto field = backend_->createBufferFrom(grid.field);
  auto ray_buffer = backend_->createBuffer(rays.size() * sizeof(Ray));
  auto results = backend_->createBuffer(rays.size() * sizeof(RayResult));
  constexpr int kDispatches = 40;
  std::vector<std::vector<RayResult>> got(kDispatches);
  Sequence seq(*backend_);
  for (int i = 0; i < kDispatches; ++i) {
    const std::size_t first = std::size_t(i) * 7 % 300, count = 1 + std::size_t(i) * 13 % 100;
    got[i].resize(count);
    const TraverseParams params{grid.params, kDefaultOccupiedThreshold, unsigned(count)};
    seq.upload(*ray_buffer, rays.data() + first, count * sizeof(Ray))
        .run(kernels::rayTraverse(), params,
             {ray_buffer.get(), occupancy.get(), field.get(), results.get()})
        .download(*results, got[i].data(), count * sizeof(RayResult));
  }
  const std::uint64_t waits_before = backend_->deviceWaits();
  seq.eval();
  const std::uint64_t waits = backend_->deviceWaits() - waits_before;
  EXPECT_EQ(waits,
            GetParam() == BackendKind::kVulkan ? 2u : (GetParam() == BackendKind::kCpu ? 0u : 1u));
  const std::vector<RayResult> want = cpuTraverse(grid, rays);
  for (int i = 0; i < kDispatches; ++i) {
    const std::size_t first = std::size_t(i) * 7 % 300;
    expectSameWalks(
        got[i], std::vector<RayResult>(want.begin() + first, want.begin() + first + got[i].size()),
        "dispatch " + std::to_string(i));
  }
}

// Recording checks what run(), upload() and download() check, and records nothing on error.
TEST_P(BackendTest, SequenceChecksWhenRecording) {
  const DenseGrid grid = makeCanopyGrid(16, 0.01f, 1);
  auto occupancy = backend_->createBufferFrom(grid.occupancy);
  auto rays = backend_->createBuffer(sizeof(Ray));
  auto results = backend_->createBuffer(sizeof(RayResult));
  const TraverseParams params{grid.params, kDefaultOccupiedThreshold, 1};
  Sequence seq(*backend_);
  const float four[4] = {1.0f, 2.0f, 3.0f, 4.0f};
  seq.upload(*rays, four, sizeof(four));
  EXPECT_THROW(
      seq.run(kernels::rayTraverse(), params, {rays.get(), occupancy.get(), results.get()}),
      std::invalid_argument);
  EXPECT_THROW(seq.upload(*results, four, sizeof(four), sizeof(RayResult)), std::out_of_range);
  float sink[8];
  EXPECT_THROW(seq.download(*results, sink, sizeof(RayResult) + 1), std::out_of_range);
  EXPECT_EQ(seq.size(), 1u);
  const TraverseParams none{grid.params, kDefaultOccupiedThreshold, 0};
  seq.run(kernels::rayTraverse(), none,
          {rays.get(), occupancy.get(), occupancy.get(), results.get()});
  EXPECT_EQ(seq.size(), 1u);  // no work items: nothing recorded
  seq.eval();
  float back[4] = {};
  backend_->download(*rays, back, sizeof(back));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(back[i], four[i]);
}

TEST(KernelDescriptors, EveryKernelHasItsCodeAndDistinctBindingNames) {
  for (const KernelDescriptor* kernel : allKernels()) {
    SCOPED_TRACE(std::string(kernel->name));
    EXPECT_GT(kernel->params_bytes, 0u);
    EXPECT_NE(kernel->cpu, nullptr);
    EXPECT_NE(kernel->item_count, nullptr);
    for (std::size_t i = 0; i < kernel->bindings.size(); ++i) {
      EXPECT_NE(kernel->bindings[i].required_elements, nullptr);
      for (std::size_t j = 0; j < i; ++j)
        EXPECT_NE(kernel->bindings[i].name, kernel->bindings[j].name);
    }
  }
}

TEST_P(BackendTest, EmptyBatchIsANoOp) {
  const DenseGrid grid = makeCanopyGrid(16, 0.01f, 1);
  EXPECT_TRUE(traverseOnBackend(*backend_, grid, {}).empty());
}

TEST_P(BackendTest, MatchesCpuOnFixedWorkload) {
  const DenseGrid grid = makeCanopyGrid(64, 0.002f, 5);
  expectSameAsCpu(grid, makeRandomRays(grid.params, {20000, 0.5f}, 6), "fixed seed 5/6");
}

TEST_P(BackendTest, MatchesCpuOnFreshRandomWorkloads) {
  for (int round = 0; round < 3; ++round) {
    const std::uint64_t seed = fvp::testing::freshSeed();
    std::mt19937_64 rng(seed);
    const int side = 8 + static_cast<int>(rng() % 90);
    const float voxel = 0.001f * (1 + static_cast<int>(rng() % 10));
    const DenseGrid grid = makeCanopyGrid(side, voxel, seed);
    const auto rays = makeRandomRays(grid.params, {5000, 0.5f}, seed + 1);
    SCOPED_TRACE(fvp::testing::replayHint(seed));
    expectSameAsCpu(grid, rays, "seed " + std::to_string(seed));
    if (HasFatalFailure()) return;
  }
}

TEST_P(BackendTest, MatchesCpuOnBoundaryCases) {
  // Axis-aligned, diagonal-through-corners, zero-length, outside, NaN and far rays.
  const float v = 1.0f / 64.0f;
  DenseGrid grid = makeCanopyGrid(16, v, 3);
  const float lo = grid.params.origin_x_m, hi = lo + 16 * v;
  const float nan = std::nanf("");
  std::vector<Ray> rays = {
      makeRay({lo + 2.5f * v, 0, 0}, {hi - 0.5f * v, 0, 0}),
      makeRay({0, hi - 0.5f * v, 0}, {0, lo + 0.5f * v, 0}),
      makeRay({0, 0, lo + 0.5f * v}, {0, 0, hi - 0.5f * v}),
      makeRay({lo + 2.5f * v, lo + 2.5f * v, lo + 2.5f * v},
              {hi - 2.5f * v, hi - 2.5f * v, hi - 2.5f * v}),
      makeRay({lo - 2 * v, lo - 2 * v, 0.5f * v}, {hi, hi, 0.5f * v}),
      makeRay({0.3f * v, 0.3f * v, 0.3f * v}, {0.3f * v, 0.3f * v, 0.3f * v}),
      makeRay({lo - 1.0f, 0, 0}, {lo - 2.0f, 0, 0}),
      makeRay({nan, 0, 0}, {0, 0, 0}),
      makeRay({0, 0, 0}, {0, 0, 1000.0f}),
      makeRay({lo, lo, lo}, {hi, hi, hi}),
  };
  expectSameAsCpu(grid, rays, "boundary cases");
}

FVP_INSTANTIATE_FOR_ALL_BACKENDS(BackendTest);

TEST(BackendFactory, ChoiceNamesRoundTrip) {
  for (const BackendChoice choice : kBackendChoices)
    EXPECT_EQ(parseBackendChoice(toString(choice)), choice) << toString(choice);
  EXPECT_FALSE(parseBackendChoice("gpu").has_value());
  EXPECT_FALSE(parseBackendChoice("").has_value());
  EXPECT_EQ(backendChoiceNames(), "auto, cpu, opencl, vulkan");
  EXPECT_EQ(createBackend(BackendChoice::kCpu)->kind(), BackendKind::kCpu);
}

TEST(BackendFactory, NamesAndErrors) {
  EXPECT_EQ(parseBackendKind("opencl"), BackendKind::kOpenCl);
  EXPECT_FALSE(parseBackendKind("auto").has_value());
  EXPECT_FALSE(parseBackendKind("cuda").has_value());
  try {
    createBackend("cuda");
    FAIL() << "an unknown backend name must throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cuda"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("expected one of auto, cpu, opencl, vulkan"),
              std::string::npos);
  }
  // auto always yields a working backend: a GPU where there is one, else the reference.
  auto backend = createBackend("auto");
  ASSERT_TRUE(backend);
  EXPECT_FALSE(backend->deviceName().empty());
}

TEST(BackendFactory, ProbeListsEveryBackend) {
  const auto infos = probeBackends();
  ASSERT_EQ(infos.size(), 3u);
  EXPECT_EQ(infos[0].kind, BackendKind::kCpu);
  EXPECT_TRUE(infos[0].available);
  for (const auto& info : infos) {
    if (info.available) {
      EXPECT_FALSE(info.device.empty());
    } else {
      EXPECT_FALSE(info.reason.empty()) << toString(info.kind) << " must say why it is unavailable";
    }
    if (fvp::testing::allBackendsRequired()) {
      EXPECT_TRUE(info.available) << toString(info.kind) << ": " << info.reason;
    }
  }
}

}  // namespace
}  // namespace fvp::accel
