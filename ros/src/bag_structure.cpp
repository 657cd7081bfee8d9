// ROS bag 2.0 records walked as the format defines them (http://wiki.ros.org/Bags/Format/2.0):
// <header_len uint32><header: fields <len uint32><name>=<value>><data_len uint32><data>.
#include "fvp/ros/bag_structure.h"

#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace fvp::ros {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint64_t kMagicBytes = sizeof(kMagic) - 1;
constexpr std::uint8_t kMessageData = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05,
                       kChunkInfo = 0x06, kConnection = 0x07;
/// A record header holds a few fields and, for a connection, its message definition: far less.
constexpr std::uint32_t kMaxHeaderBytes = std::uint32_t{16} << 20;

struct Record {
  std::uint64_t offset = 0;  ///< of its header_len
  std::map<std::string, std::string> fields;
  std::uint64_t data_offset = 0;
  std::uint32_t data_len = 0;
  std::uint64_t end() const { return data_offset + data_len; }
};

class BagWalker {
 public:
  explicit BagWalker(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) fail(0, "the file", "a readable file");
    in_.seekg(0, std::ios::end);
    size_ = std::uint64_t(in_.tellg());
  }

  [[noreturn]] void fail(std::uint64_t offset, const std::string& field,
                         const std::string& expected) const {
    throw std::runtime_error(path_.string() + ": not a readable ROS bag: at byte " +
                             std::to_string(offset) + ", " + field + ": expected " + expected);
  }

  std::uint64_t size() const { return size_; }

  std::string bytes(std::uint64_t offset, std::uint64_t n) {
    std::string out(n, '\0');
    in_.seekg(std::streamoff(offset));
    if (!in_.read(out.data(), std::streamsize(n))) fail(offset, "the file", "more bytes");
    return out;
  }

  std::uint32_t u32(std::uint64_t offset) {
    const std::string b = bytes(offset, 4);
    std::uint32_t v = 0;
    std::memcpy(&v, b.data(), 4);  // little-endian, as bags are and x86 is
    return v;
  }

  /// The record at offset, which must end by `limit`.
  Record record(std::uint64_t offset, std::uint64_t limit) {
    Record r;
    r.offset = offset;
    if (limit < offset + 4) fail(offset, "header_len", "4 bytes before the end");
    const std::uint32_t header_len = u32(offset);
    if (header_len > kMaxHeaderBytes || header_len > limit - offset - 4)
      fail(offset, "header_len " + std::to_string(header_len), "a header inside the file");
    const std::string header = bytes(offset + 4, header_len);
    for (std::uint64_t at = 0; at < header.size();) {
      if (header.size() - at < 4) fail(offset + 4 + at, "a header field", "its 4-byte length");
      std::uint32_t len = 0;
      std::memcpy(&len, header.data() + at, 4);
      if (len > header.size() - at - 4)
        fail(offset + 4 + at, "a header field's length", "a field inside its header");
      const std::string field = header.substr(at + 4, len);
      const auto eq = field.find('=');
      if (eq == std::string::npos) fail(offset + 4 + at, "a header field", "name=value");
      r.fields[field.substr(0, eq)] = field.substr(eq + 1);
      at += 4 + std::uint64_t(len);
    }
    const std::uint64_t data_len_at = offset + 4 + header_len;
    if (limit < data_len_at + 4) fail(data_len_at, "data_len", "4 bytes before the end");
    r.data_len = u32(data_len_at);
    r.data_offset = data_len_at + 4;
    if (r.data_len > limit - r.data_offset)
      fail(data_len_at, "data_len " + std::to_string(r.data_len), "data inside the file");
    return r;
  }

  std::uint8_t op(const Record& r) {
    const auto it = r.fields.find("op");
    if (it == r.fields.end() || it->second.size() != 1) fail(r.offset, "op", "a 1-byte op field");
    return std::uint8_t(it->second[0]);
  }

  template <typename T>
  T number(const Record& r, const std::string& name) {
    const auto it = r.fields.find(name);
    if (it == r.fields.end() || it->second.size() != sizeof(T))
      fail(r.offset, name, "a " + std::to_string(sizeof(T)) + "-byte field");
    T v{};
    std::memcpy(&v, it->second.data(), sizeof(T));
    return v;
  }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

/// A chunk as its index records may point into it.
struct ChunkSeen {
  std::uint32_t size = 0;                                ///< uncompressed
  std::optional<std::set<std::uint64_t>> record_starts;  ///< known when not compressed
};

/// The records inside an uncompressed chunk: where each starts, relative to the chunk's data.
std::set<std::uint64_t> chunkRecords(BagWalker& bag, const Record& chunk) {
  std::set<std::uint64_t> starts;
  for (std::uint64_t at = chunk.data_offset; at < chunk.end();) {
    const Record r = bag.record(at, chunk.end());
    const std::uint8_t op = bag.op(r);
    if (op != kMessageData && op != kConnection)
      bag.fail(at, "op", "a message or connection record inside a chunk");
    starts.insert(at - chunk.data_offset);
    at = r.end();
  }
  return starts;
}

ChunkSeen checkChunk(BagWalker& bag, const Record& r) {
  const auto compression = r.fields.find("compression");
  if (compression == r.fields.end()) bag.fail(r.offset, "compression", "a chunk's compression");
  ChunkSeen chunk;
  chunk.size = bag.number<std::uint32_t>(r, "size");
  if (chunk.size > kMaxBagChunkBytes)
    bag.fail(r.offset, "size " + std::to_string(chunk.size),
             "a chunk of at most " + std::to_string(kMaxBagChunkBytes >> 20) + " MiB");
  if (compression->second == "none") {
    if (chunk.size != r.data_len) bag.fail(r.offset, "size", "data_len, for an uncompressed chunk");
    chunk.record_starts = chunkRecords(bag, r);
  } else if (compression->second != "bz2" && compression->second != "lz4") {
    bag.fail(r.offset, "compression '" + compression->second + "'", "none, bz2 or lz4");
  }
  return chunk;
}

/// An index record's entries (time, offset) point at messages of the chunk before it.
void checkIndex(BagWalker& bag, const Record& r, const std::optional<ChunkSeen>& chunk) {
  if (bag.number<std::uint32_t>(r, "ver") != 1) bag.fail(r.offset, "ver", "index version 1");
  const std::uint32_t count = bag.number<std::uint32_t>(r, "count");
  if (std::uint64_t(count) * 12 != r.data_len)
    bag.fail(r.offset, "count", "12 bytes of data per entry");
  if (!chunk) bag.fail(r.offset, "index data", "a chunk before it");
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t offset = bag.u32(r.data_offset + 12 * std::uint64_t(i) + 8);
    const bool inside = chunk->record_starts ? chunk->record_starts->count(offset) > 0
                                             : std::uint64_t(offset) + 8 <= chunk->size;
    if (!inside)
      bag.fail(r.offset, "entry " + std::to_string(i) + "'s offset", "a record of its chunk");
  }
}

}  // namespace

void checkBagStructure(const std::filesystem::path& path) {
  BagWalker bag(path);
  if (bag.size() < kMagicBytes || bag.bytes(0, kMagicBytes) != kMagic)
    bag.fail(0, "the version line", "#ROSBAG V2.0");
  std::set<std::uint64_t> record_starts, chunk_starts;
  std::optional<std::uint64_t> index_pos;
  std::optional<ChunkSeen> last_chunk;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> chunk_infos;  // (record, chunk_pos)
  for (std::uint64_t at = kMagicBytes; at < bag.size();) {
    const Record r = bag.record(at, bag.size());
    record_starts.insert(at);
    switch (bag.op(r)) {
      case kBagHeader:
        if (index_pos) bag.fail(at, "bag header", "one bag header");
        index_pos = bag.number<std::uint64_t>(r, "index_pos");
        break;
      case kChunk:
        last_chunk = checkChunk(bag, r);
        chunk_starts.insert(at);
        break;
      case kIndexData:
        checkIndex(bag, r, last_chunk);
        break;
      case kChunkInfo:
        chunk_infos.emplace_back(at, bag.number<std::uint64_t>(r, "chunk_pos"));
        if (std::uint64_t(bag.number<std::uint32_t>(r, "count")) * 8 != r.data_len)
          bag.fail(at, "count", "8 bytes of data per connection");
        break;
      case kConnection:
        bag.number<std::uint32_t>(r, "conn");
        break;
      default:
        bag.fail(at, "op", "a bag, chunk, index, chunk info or connection record");
    }
    at = r.end();
  }
  if (!index_pos) bag.fail(kMagicBytes, "bag header", "a bag header first");
  if (*index_pos != 0 && !record_starts.count(*index_pos))
    bag.fail(kMagicBytes, "index_pos", "the start of a record");
  for (const auto& [at, chunk_pos] : chunk_infos)
    if (!chunk_starts.count(chunk_pos)) bag.fail(at, "chunk_pos", "the start of a chunk");
}

namespace {

/// A cursor over a serialized message: each read fails (returns false) past the end.
class Serialized {
 public:
  Serialized(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool skip(std::uint64_t n) {
    if (n > size_ - at_) return false;
    at_ += std::size_t(n);
    return true;
  }
  bool u32(std::uint32_t& v) {
    if (size_ - at_ < 4) return false;
    std::memcpy(&v, data_ + at_, 4);
    at_ += 4;
    return true;
  }
  /// A string or uint8 array: its length, then that many bytes.
  bool bytes() { return array(1); }
  /// A variable array of fixed-size elements.
  bool array(std::uint64_t element_bytes) {
    std::uint32_t n = 0;
    return u32(n) && skip(std::uint64_t(n) * element_bytes);
  }
  bool header() { return skip(4 + 8) && bytes(); }  // seq, stamp, frame_id
  bool image() {
    return header() && skip(4 + 4) && bytes() && skip(1 + 4) && bytes();  // ..., data
  }
  bool done() const { return at_ == size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

constexpr std::uint64_t kRegionOfInterestBytes = 4 * 4 + 1;

}  // namespace

bool serializedMessageFits(BagMessage type, const std::uint8_t* data, std::size_t size) {
  Serialized m(data, size);
  switch (type) {
    case BagMessage::kTf: {
      std::uint32_t count = 0;
      if (!m.u32(count)) return false;
      for (std::uint32_t i = 0; i < count; ++i)  // each at least 20 bytes: ends by size / 20
        if (!(m.header() && m.bytes() && m.skip(7 * 8))) return false;
      return m.done();
    }
    case BagMessage::kImage:
      return m.image() && m.done();
    case BagMessage::kCameraInfo:
      return m.header() && m.skip(4 + 4) && m.bytes() && m.array(8) && m.skip((9 + 9 + 12) * 8) &&
             m.skip(4 + 4 + kRegionOfInterestBytes) && m.done();
    case BagMessage::kDisparityImage:
      return m.header() && m.image() && m.skip(4 + 4 + kRegionOfInterestBytes + 3 * 4) && m.done();
  }
  return false;
}

}  // namespace fvp::ros
