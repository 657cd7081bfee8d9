#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>

namespace fvp::host::map {

// A set of OctoMap keys for one scan's update, in place of octomap::KeySet
// (std::tr1::unordered_set, one heap node per key): the keys are packed into 48 bits of
// one 64-bit word and stored by open addressing with linear probing, so inserting is a
// probe into one flat array and never allocates per key. It is what makes the octomap
// engine's observation-box update (millions of keys a frame) cheaper than
// OcTree::insertPointCloud on the same frame (bench BM_ScanIntegrateFineBox).
//
// Insert and look-up only: a scan never removes a key (free-minus-occupied is a
// `contains` test when the keys are applied).
class OcTreeKeySet {
 public:
  using Packed = std::uint64_t;

  static Packed pack(const octomap::OcTreeKey& key) {
    return Packed{key[0]} | Packed{key[1]} << 16 | Packed{key[2]} << 32;
  }
  static octomap::OcTreeKey unpack(Packed packed) {
    return octomap::OcTreeKey(static_cast<octomap::key_type>(packed & 0xffff),
                              static_cast<octomap::key_type>(packed >> 16 & 0xffff),
                              static_cast<octomap::key_type>(packed >> 32 & 0xffff));
  }
  // A well-mixed 64-bit hash of a packed key (splitmix64's finaliser): neighbouring
  // voxels must not land in neighbouring slots, or linear probing degrades into runs.
  static std::uint64_t hash(Packed packed) {
    std::uint64_t z = packed + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

  OcTreeKeySet() = default;

  // True when the key was not in the set yet.
  bool insert(const octomap::OcTreeKey& key) { return insertPacked(pack(key)); }
  bool insertPacked(Packed packed) {
    const std::uint64_t h = hash(packed);
    // Neighbouring rays cross mostly the same voxels: most inserts repeat a key inserted
    // a few rays ago. A small direct-mapped cache of recent keys (L2-sized) answers those
    // without touching the table, which is far larger than the cache for a whole frame.
    Packed& recent = recent_[(h >> 20) & (kRecentSlots - 1)];
    if (recent == packed) return false;
    if ((size_ + 1) * 2 > slots_.size()) grow();
    const bool inserted = insertIntoTable(packed, h);
    recent = packed;  // only once it is in the table (grow may throw)
    return inserted;
  }

  bool contains(const octomap::OcTreeKey& key) const { return containsPacked(pack(key)); }
  bool containsPacked(Packed packed) const {
    if (size_ == 0) return false;
    for (std::size_t i = hash(packed) & mask_;; i = (i + 1) & mask_) {
      if (slots_[i] == packed) return true;
      if (slots_[i] == kEmpty) return false;
    }
  }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  // Calls f(packed) for every key, in slot order (deterministic for a given insert
  // sequence, not sorted).
  template <typename F>
  void forEachPacked(F&& f) const {
    for (const Packed packed : slots_) {
      if (packed != kEmpty) f(packed);
    }
  }

 private:
  // No packed key has bits above 48 set.
  static constexpr Packed kEmpty = ~Packed{0};
  static constexpr std::size_t kInitialSlots = 1024;
  static constexpr std::size_t kRecentSlots = 8192;

  void grow() {
    // The new table is built before the old one is let go, so a failed allocation leaves
    // the set as it was.
    std::vector<Packed> previous(slots_.empty() ? kInitialSlots : slots_.size() * 2, kEmpty);
    previous.swap(slots_);  // slots_ is now the empty, larger table
    mask_ = slots_.size() - 1;
    size_ = 0;
    for (const Packed packed : previous) {
      if (packed != kEmpty) insertIntoTable(packed, hash(packed));
    }
  }

  bool insertIntoTable(Packed packed, std::uint64_t h) {
    for (std::size_t i = h & mask_;; i = (i + 1) & mask_) {
      if (slots_[i] == packed) return false;
      if (slots_[i] == kEmpty) {
        slots_[i] = packed;
        ++size_;
        return true;
      }
    }
  }

  std::vector<Packed> slots_;
  std::vector<Packed> recent_ = std::vector<Packed>(kRecentSlots, kEmpty);
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace fvp::host::map
