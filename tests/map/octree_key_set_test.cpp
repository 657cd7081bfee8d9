// OcTreeKeySet, the octomap engine's per-scan key set, against std::set on the same
// inserts: keys that repeat (as neighbouring rays repeat them), growth past many
// rehashes, and keys at the ends of the 16-bit range.
#include "fvp/host/map/octree_key_set.h"

#include <cstdint>
#include <random>
#include <set>

#include <gtest/gtest.h>

namespace fvp::host::map {
namespace {

TEST(OcTreeKeySet, PackIsInvertibleOverTheWholeKeyRange) {
  for (const octomap::key_type v : {0, 1, 32767, 32768, 65534, 65535}) {
    const octomap::OcTreeKey key(v, static_cast<octomap::key_type>(65535 - v), 12345);
    EXPECT_EQ(OcTreeKeySet::unpack(OcTreeKeySet::pack(key)), key);
  }
}

TEST(OcTreeKeySet, EqualsStdSetOnRepeatedKeys) {
  std::mt19937 rng(17);
  // A walk: most keys repeat one seen a little earlier (the recent-key cache's case),
  // some jump far (the table's case).
  std::uniform_int_distribution<int> step(-1, 1), jump(0, 65535), coin(0, 99);
  OcTreeKeySet set;
  std::set<std::uint64_t> truth;
  octomap::OcTreeKey key(32768, 32768, 32768);
  for (int i = 0; i < 400000; ++i) {
    for (int a = 0; a < 3; ++a) {
      key[a] = static_cast<octomap::key_type>(coin(rng) == 0 ? jump(rng) : key[a] + step(rng));
    }
    const bool inserted_now = set.insert(key);
    EXPECT_EQ(inserted_now, truth.insert(OcTreeKeySet::pack(key)).second) << "insert " << i;
  }
  ASSERT_EQ(set.size(), truth.size());
  std::set<std::uint64_t> listed;
  set.forEachPacked([&](OcTreeKeySet::Packed p) { EXPECT_TRUE(listed.insert(p).second); });
  EXPECT_EQ(listed, truth);
  for (int i = 0; i < 100000; ++i) {
    const octomap::OcTreeKey probe(static_cast<octomap::key_type>(jump(rng)),
                                   static_cast<octomap::key_type>(jump(rng)),
                                   static_cast<octomap::key_type>(jump(rng)));
    EXPECT_EQ(set.contains(probe), truth.count(OcTreeKeySet::pack(probe)) == 1);
  }
  for (const std::uint64_t p : truth) EXPECT_TRUE(set.containsPacked(p));
}

TEST(OcTreeKeySet, EmptySetContainsNothing) {
  const OcTreeKeySet set;
  EXPECT_TRUE(set.empty());
  EXPECT_FALSE(set.contains(octomap::OcTreeKey(0, 0, 0)));
  int visited = 0;
  set.forEachPacked([&](OcTreeKeySet::Packed) { ++visited; });
  EXPECT_EQ(visited, 0);
}

}  // namespace
}  // namespace fvp::host::map
