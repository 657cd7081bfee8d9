// A check of a ROS bag's record structure before rosbag reads it (docs/ros.md). rosbag trusts
// the lengths a file states: a header length of 4 GB makes it allocate 4 GB (found by the
// stereo_bag fuzz harness), a chunk's stated size is what it decompresses into, and an index
// offset is where it reads in the chunk. This walks the file as the format defines it
// (http://wiki.ros.org/Bags/Format/2.0) and refuses what would send rosbag outside the file or
// past the limits below. Plain C++: no ROS header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>

namespace fvp::ros {

/// The largest chunk rosbag may be asked to decompress: a recorder closes a chunk past its
/// threshold (768 KB by default), so a chunk holds at most that and one message, and one
/// message (a 12 MP colour image is 36 MB) is far below this.
inline constexpr std::uint32_t kMaxBagChunkBytes = std::uint32_t{256} << 20;

/// Throws std::runtime_error naming the file, the byte offset and the field when the bag is
/// not a version 2.0 bag whose records, chunks and indices all lie inside the file.
void checkBagStructure(const std::filesystem::path& bag);

/// The messages the stereo reader deserializes.
enum class BagMessage { kTf, kImage, kCameraInfo, kDisparityImage };

/// Whether a message's serialized bytes hold every string, array and field its type states,
/// by ROS 1's serialization (little-endian; uint32 lengths before strings and variable arrays).
/// roscpp's deserializer sizes each string and array by its stated length before it reads it,
/// so a length past the message's end would allocate what the file never held (the stereo_bag
/// fuzz harness found a tf message stating 4 billion transforms). Plain C++: no ROS header.
bool serializedMessageFits(BagMessage type, const std::uint8_t* data, std::size_t size);

}  // namespace fvp::ros
