#include "OpenABLE/io/rosbag_check.h"

#include <bzlib.h>
#include <lz4.h>
#include <ros/message_traits.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

// The first line of a bag of format 2.0.
constexpr std::string_view kVersionLine("#ROSBAG V2.0\n", 13);
// Record headers beyond this are refused before they are read (rosbag_storage would allocate
// them: they hold a few fields, a connection's message definition at most, some KB).
constexpr std::uint64_t kMaxHeader = std::uint64_t{16} << 20;
// Chunks (as stored and decompressed) beyond this are refused: rosbag record closes a chunk
// at 768 KB, so only a message of more than 1 GiB would make one.
constexpr std::uint64_t kMaxChunk = std::uint64_t{1} << 30;

// The record ops of format 2.0.
constexpr std::uint8_t kMessageData = 0x02, kFileHeader = 0x03, kIndexData = 0x04, kChunk = 0x05,
                       kChunkInfo = 0x06, kConnection = 0x07;

// A defect found: thrown inside this file, returned by BagDefect as its text.
struct Defect {
  std::string what;
};
[[noreturn]] void Fail(const std::string& what) { throw Defect{what}; }

std::uint64_t Little(std::string_view bytes) {  // little-endian, up to 8 bytes
  std::uint64_t v = 0;
  for (std::size_t i = bytes.size(); i-- > 0;) v = (v << 8) | static_cast<unsigned char>(bytes[i]);
  return v;
}

std::string At(std::uint64_t pos) { return " at byte " + std::to_string(pos); }

// The fields of a header in ros::Header's layout: fields of a 4-byte length then
// "name=value"; a later field of the same name replaces an earlier one, as in ros::Header.
// ros::Header::parse reads a length past the end of the header as it is: each is checked here.
using Fields = std::map<std::string, std::string>;
Fields ParseFields(std::string_view header, const std::string& what) {
  Fields fields;
  std::size_t i = 0;
  while (i < header.size()) {
    if (header.size() - i < 4)
      Fail(what + " ends inside the length of a field (" + std::to_string(header.size() - i) +
           " of its 4 bytes)");
    const std::uint64_t length = Little(header.substr(i, 4));
    i += 4;
    if (length > header.size() - i)
      Fail(what + " has a field of " + std::to_string(length) + " bytes where " +
           std::to_string(header.size() - i) + " are left");
    const std::string_view field = header.substr(i, length);
    i += length;
    const std::size_t equals = field.find('=');
    if (equals == std::string_view::npos) Fail(what + " has a field without '='");
    fields[std::string(field.substr(0, equals))] = std::string(field.substr(equals + 1));
  }
  return fields;
}

// Field `name` of `fields`: present and, when `size` > 0, of that many bytes.
const std::string& Field(const Fields& fields, const char* name, std::size_t size,
                         const std::string& what) {
  const auto found = fields.find(name);
  if (found == fields.end()) Fail(what + " has no field \"" + name + "\"");
  if (size > 0 && found->second.size() != size)
    Fail(what + "'s field \"" + name + "\" has " + std::to_string(found->second.size()) +
         " bytes; expected " + std::to_string(size));
  return found->second;
}
std::uint64_t Number(const Fields& fields, const char* name, std::size_t size,
                     const std::string& what) {
  return Little(Field(fields, name, size, what));
}
void RequireOp(const Fields& fields, std::uint8_t op, const char* kind, const std::string& what) {
  const auto found = Number(fields, "op", 1, what);
  if (found != op)
    Fail(what + " is a record of op " + std::to_string(found) + "; expected " + kind);
}

// A record: a 4-byte header length, the header, a 4-byte data length, the data.
struct Record {
  Fields fields;
  std::uint64_t data_pos = 0, data_length = 0;
  std::uint64_t End() const { return data_pos + data_length; }
};

// The bag, read in bounded pieces.
class BagFile {
 public:
  explicit BagFile(const std::string& path) : in_(path, std::ios::binary) {
    if (!in_) Fail("it cannot be opened");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
  }

  std::uint64_t Size() const { return size_; }

  // The `n` bytes at `pos`, which must be in the file.
  std::string Read(std::uint64_t pos, std::uint64_t n, const std::string& what) {
    if (pos > size_ || n > size_ - pos)
      Fail(what + " is cut short: it needs bytes " + std::to_string(pos) + " to " +
           std::to_string(pos + n) + " of a file of " + std::to_string(size_));
    std::string bytes(n, '\0');
    in_.seekg(static_cast<std::streamoff>(pos));
    if (!in_.read(bytes.data(), static_cast<std::streamsize>(n))) Fail(what + ": a read error");
    return bytes;
  }

  // The record at `pos`: its header parsed, its data within the file (not read).
  Record ReadRecord(std::uint64_t pos, const std::string& what) {
    const std::uint64_t header_length = Little(Read(pos, 4, what));
    if (header_length > kMaxHeader)
      Fail(what + " announces a header of " + std::to_string(header_length) + " bytes");
    Record r;
    r.fields = ParseFields(Read(pos + 4, header_length, what), what + "'s header");
    r.data_length = Little(Read(pos + 4 + header_length, 4, what));
    r.data_pos = pos + 8 + header_length;
    if (r.data_length > size_ - r.data_pos)
      Fail(what + " is cut short: its data of " + std::to_string(r.data_length) +
           " bytes runs past the end of the file");
    return r;
  }

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0;
};

struct Connection {
  std::string topic, md5sum;
};

// An index entry: the message at `offset` of its chunk, of `connection`.
struct Entry {
  std::uint32_t offset, connection;
};

// A chunk's data decompressed with libbz2, as rosbag_storage does (BZ2_bzBuffToBuffDecompress
// into `size` bytes): it must give exactly `size` bytes.
std::string Bz2(const std::string& stored, std::uint64_t size, const std::string& what) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) Fail(what + ": libbz2 cannot start");
  const std::unique_ptr<bz_stream, int (*)(bz_stream*)> end(&s, BZ2_bzDecompressEnd);
  s.next_in = const_cast<char*>(stored.data());
  s.avail_in = static_cast<unsigned>(stored.size());
  std::string out;
  std::vector<char> piece(1 << 20);  // grown by what the data gives, not by what `size` says
  while (true) {
    s.next_out = piece.data();
    s.avail_out = static_cast<unsigned>(piece.size());
    const int r = BZ2_bzDecompress(&s);
    const std::size_t produced = piece.size() - s.avail_out;
    if (out.size() + produced > size)
      Fail(what + " decompresses to more than the " + std::to_string(size) +
           " bytes its header says");
    out.append(piece.data(), produced);
    if (r == BZ_STREAM_END) break;
    if (r != BZ_OK) Fail(what + " holds damaged bz2 data (libbz2 error " + std::to_string(r) + ")");
    if (s.avail_in == 0 && produced == 0) Fail(what + "'s bz2 data ends early");
  }
  if (out.size() != size)
    Fail(what + " decompresses to " + std::to_string(out.size()) + " bytes; its header says " +
         std::to_string(size));
  return out;
}

// A chunk's data as roslz4 decompresses it: a frame of LZ4's format (magic, flags, block size,
// header checksum) with the flags roslz4 writes; blocks of a 4-byte size (high bit: stored as
// is) and their bytes, each at most the frame's block size (roslz4 copies a block into a buffer
// of that size without checking); a size of 0 ends it (roslz4 then checks the content's
// checksum, which is left to it). It must give exactly `size` bytes.
std::string Lz4(const std::string& stored, std::uint64_t size, const std::string& what) {
  const std::string_view in(stored);
  if (in.size() < 7 || Little(in.substr(0, 4)) != 0x184D2204)
    Fail(what + " does not hold an LZ4 frame");
  const auto flags = static_cast<unsigned char>(in[4]);
  const auto block = static_cast<unsigned char>(in[5]);
  const int block_id = (block >> 4) & 7;
  // Version 1, independent blocks, no block checksums, a content checksum, no content size, no
  // dictionary, reserved bits 0: what roslz4 writes and reads.
  if (flags != 0x64 || (block & 0x8F) != 0 || block_id < 4)
    Fail(what + " holds an LZ4 frame with flags " + std::to_string(flags) + " and block byte " +
         std::to_string(block) + "; expected those roslz4 writes");
  const std::size_t block_max = std::size_t{1} << (8 + 2 * block_id);
  std::vector<char> piece(block_max);
  std::string out;
  for (std::size_t pos = 7;;) {
    if (in.size() - pos < 4) Fail(what + "'s LZ4 frame ends inside a block size");
    const std::uint64_t word = Little(in.substr(pos, 4));
    pos += 4;
    const std::size_t n = word & 0x7FFFFFFF;
    if (n == 0) break;  // the end mark (roslz4 takes a stored block of 0 bytes for it too)
    if (n > block_max)
      Fail(what + "'s LZ4 frame has a block of " + std::to_string(n) + " bytes; its blocks are " +
           std::to_string(block_max) + " bytes at most");
    if (n > in.size() - pos) Fail(what + "'s LZ4 frame ends inside a block");
    std::string_view content = in.substr(pos, n);
    if ((word >> 31) == 0) {
      const int r = LZ4_decompress_safe(in.data() + pos, piece.data(), static_cast<int>(n),
                                        static_cast<int>(piece.size()));
      if (r < 0) Fail(what + "'s LZ4 frame has a damaged block");
      content = std::string_view(piece.data(), static_cast<std::size_t>(r));
    }
    pos += n;
    if (out.size() + content.size() > size)
      Fail(what + " decompresses to more than the " + std::to_string(size) +
           " bytes its header says");
    out.append(content);
  }
  if (out.size() != size)
    Fail(what + " decompresses to " + std::to_string(out.size()) + " bytes; its header says " +
         std::to_string(size));
  return out;
}

// A message as ROS serialises it, walked field by field; false when a field runs past it.
class Serialized {
 public:
  explicit Serialized(std::string_view bytes) : bytes_(bytes) {}
  bool Skip(std::size_t n) {
    if (n > bytes_.size() - i_) return false;
    i_ += n;
    return true;
  }
  // A string or a byte array: a 4-byte length, then its bytes.
  bool Sized() {
    if (bytes_.size() - i_ < 4) return false;
    const std::uint64_t n = Little(bytes_.substr(i_, 4));
    i_ += 4;
    return Skip(n);
  }
  // std_msgs/Header: seq, stamp (seconds and nanoseconds), frame_id.
  bool Header() { return Skip(4) && Skip(8) && Sized(); }

 private:
  std::string_view bytes_;
  std::size_t i_ = 0;
};

// Whether the serialised sensor_msgs/Image or CompressedImage `bytes` holds every length it
// announces: roscpp_serialization allocates an array's length before it checks it is there.
bool ImageFits(std::string_view bytes) {
  Serialized s(bytes);  // header, height, width, encoding, is_bigendian, step, data
  return s.Header() && s.Skip(8) && s.Sized() && s.Skip(5) && s.Sized();
}
bool CompressedImageFits(std::string_view bytes) {
  Serialized s(bytes);  // header, format, data
  return s.Header() && s.Sized() && s.Sized();
}

// The records of a decompressed chunk, which must fill it: the data records the index entries
// name (of a known connection; images whole).
void CheckChunk(std::string_view content, const std::vector<Entry>& entries,
                const std::map<std::uint32_t, Connection>& connections, const std::string& what) {
  std::map<std::uint64_t, std::string_view> messages;  // offset -> data of a data record
  for (std::uint64_t pos = 0; pos < content.size();) {
    const std::string record = what + "'s record" + At(pos) + " of its content";
    const std::uint64_t left = content.size() - pos;
    const std::uint64_t header_length = left >= 4 ? Little(content.substr(pos, 4)) : 0;
    if (left < 8 || header_length > left - 8) Fail(record + " is cut short");
    const Fields fields = ParseFields(content.substr(pos + 4, header_length), record);
    const std::uint64_t data_pos = pos + 8 + header_length;
    const std::uint64_t data_length = Little(content.substr(data_pos - 4, 4));
    if (data_length > content.size() - data_pos) Fail(record + " is cut short");
    if (Number(fields, "op", 1, record) == kMessageData) {
      const std::uint64_t connection = Number(fields, "conn", 4, record);
      if (connections.count(static_cast<std::uint32_t>(connection)) == 0)
        Fail(record + " names connection " + std::to_string(connection) +
             ", which the bag does not define");
      messages[pos] = content.substr(data_pos, data_length);
    }
    pos = data_pos + data_length;
  }
  const std::string image_md5 = ros::message_traits::MD5Sum<sensor_msgs::Image>::value();
  const std::string compressed_md5 =
      ros::message_traits::MD5Sum<sensor_msgs::CompressedImage>::value();
  for (const Entry& e : entries) {
    const auto message = messages.find(e.offset);
    if (message == messages.end())
      Fail("an index entry of " + what + " names byte " + std::to_string(e.offset) +
           " of its content, where no message record begins");
    const Connection& c = connections.at(e.connection);
    const bool image = c.md5sum == image_md5, compressed = c.md5sum == compressed_md5;
    if ((image && !ImageFits(message->second)) ||
        (compressed && !CompressedImageFits(message->second)))
      // The bytes do not fit the type the connection declares: a message of another type
      // filed under it (rosbag's writer files a topic's messages under its first connection
      // unless each comes with its own connection header) or damage; a bag cannot tell which.
      Fail("the message of topic " + Quoted(c.topic) + At(e.offset) + " of " + what +
           " does not decode as " + (image ? "sensor_msgs/Image" : "sensor_msgs/CompressedImage") +
           ", the type its connection declares (a field's length runs past its " +
           std::to_string(message->second.size()) +
           " bytes): a message of another type written on the topic, or damage");
  }
}

// Each record rosbag_storage's Bag::open reads, in its order, then each chunk that index
// entries name with the messages they name.
void Check(BagFile& bag) {
  const std::string first = bag.Read(0, std::min<std::uint64_t>(bag.Size(), 13), "it");
  if (first != kVersionLine) {
    if (first.compare(0, 9, "#ROSBAG V") == 0)
      Fail("it is a bag of format " + Quoted(first.substr(9, first.find('\n') - 9)) +
           "; OpenABLE reads format 2.0 (rosbag record since 2010)");
    Fail("it is not a ROS 1 bag (its first line is not \"#ROSBAG V2.0\")");
  }
  const std::string file_header = "its file header";
  const Record header = bag.ReadRecord(kVersionLine.size(), file_header);
  RequireOp(header.fields, kFileHeader, "a file header", file_header);
  const auto encryptor = header.fields.find("encryptor");
  if (encryptor != header.fields.end() && !encryptor->second.empty())
    Fail("it is encrypted (" + Quoted(encryptor->second) + "), which OpenABLE does not read");
  const std::uint64_t index_pos = Number(header.fields, "index_pos", 8, file_header);
  if (index_pos == 0) Fail("it has no index: a recording cut short (rosbag reindex repairs it)");
  const std::uint64_t connection_count = Number(header.fields, "conn_count", 4, file_header);
  const std::uint64_t chunk_count = Number(header.fields, "chunk_count", 4, file_header);

  // The connection records, then the chunk infos, from index_pos.
  std::map<std::uint32_t, Connection> connections;
  std::uint64_t pos = index_pos;
  for (std::uint64_t i = 0; i < connection_count; ++i) {
    const std::string what = "its connection record" + At(pos);
    const Record r = bag.ReadRecord(pos, what);
    RequireOp(r.fields, kConnection, "a connection record", what);
    const auto id = static_cast<std::uint32_t>(Number(r.fields, "conn", 4, what));
    const std::string& topic = Field(r.fields, "topic", 0, what);
    if (r.data_length > kMaxHeader)  // read as a header too
      Fail(what + " announces a connection header of " + std::to_string(r.data_length) + " bytes");
    const Fields c =
        ParseFields(bag.Read(r.data_pos, r.data_length, what), what + "'s connection header");
    const auto md5sum = c.find("md5sum");
    connections.emplace(id, Connection{topic, md5sum == c.end() ? "" : md5sum->second});
    pos = r.End();
  }
  struct ChunkInfo {
    std::uint64_t pos;
    std::size_t connections;  // distinct: one index record each after the chunk
  };
  std::vector<ChunkInfo> chunks;
  for (std::uint64_t i = 0; i < chunk_count; ++i) {
    const std::string what = "its chunk info record" + At(pos);
    const Record r = bag.ReadRecord(pos, what);
    RequireOp(r.fields, kChunkInfo, "a chunk info record", what);
    if (Number(r.fields, "ver", 4, what) != 1) Fail(what + " is not of version 1");
    const std::uint64_t chunk_pos = Number(r.fields, "chunk_pos", 8, what);
    Number(r.fields, "start_time", 8, what);
    Number(r.fields, "end_time", 8, what);
    const std::uint64_t count = Number(r.fields, "count", 4, what);
    // rosbag_storage reads 8 bytes per connection whatever the data length says.
    if (r.data_length != 8 * count)
      Fail(what + " counts " + std::to_string(count) + " connections in " +
           std::to_string(r.data_length) + " bytes; expected 8 bytes each");
    const std::string data = bag.Read(r.data_pos, r.data_length, what);
    std::set<std::uint64_t> ids;
    for (std::uint64_t k = 0; k < count; ++k)
      ids.insert(Little(std::string_view(data).substr(8 * k, 4)));
    chunks.push_back({chunk_pos, ids.size()});
    pos = r.End();
  }

  // Each chunk, the index records after it, and the messages they name.
  for (const ChunkInfo& info : chunks) {
    const std::string what = "its chunk" + At(info.pos);
    const Record chunk = bag.ReadRecord(info.pos, what);
    RequireOp(chunk.fields, kChunk, "a chunk", what);
    const std::string& compression = Field(chunk.fields, "compression", 0, what);
    const std::uint64_t size = Number(chunk.fields, "size", 4, what);
    if (compression != "none" && compression != "bz2" && compression != "lz4")
      Fail(what + " is compressed with " + Quoted(compression) + "; expected none, bz2 or lz4");
    if (chunk.data_length > kMaxChunk || size > kMaxChunk)
      Fail(what + " holds " + std::to_string(chunk.data_length) + " bytes for " +
           std::to_string(size) + "; expected chunks of at most 1 GiB");
    std::vector<Entry> entries;
    std::uint64_t index = chunk.End();
    for (std::size_t k = 0; k < info.connections; ++k) {
      const std::string record = "its index record" + At(index);
      const Record r = bag.ReadRecord(index, record);
      RequireOp(r.fields, kIndexData, "an index record", record);
      if (Number(r.fields, "ver", 4, record) != 1) Fail(record + " is not of version 1");
      const auto connection = static_cast<std::uint32_t>(Number(r.fields, "conn", 4, record));
      const std::uint64_t count = Number(r.fields, "count", 4, record);
      // An unknown connection: rosbag_storage names its topic through a null pointer.
      if (connections.count(connection) == 0)
        Fail(record + " names connection " + std::to_string(connection) +
             ", which the bag does not define");
      if (r.data_length != 12 * count)  // read as 12 bytes per message, as for chunk infos
        Fail(record + " counts " + std::to_string(count) + " messages in " +
             std::to_string(r.data_length) + " bytes; expected 12 bytes each");
      const std::string data = bag.Read(r.data_pos, r.data_length, record);
      for (std::uint64_t m = 0; m < count; ++m) {
        const std::string_view entry = std::string_view(data).substr(12 * m, 12);
        const std::uint64_t sec = Little(entry.substr(0, 4)), nsec = Little(entry.substr(4, 4));
        // ros::Time normalises the nanoseconds, and throws std::runtime_error when the
        // seconds then overflow.
        if (nsec >= 1000000000)
          Fail(record + " has a time of " + std::to_string(sec) + " s and " + std::to_string(nsec) +
               " ns; expected fewer than 10^9 ns");
        if (sec == 0 && nsec == 0) continue;  // before ros::TIME_MIN: left out by the reader
        entries.push_back({static_cast<std::uint32_t>(Little(entry.substr(8, 4))), connection});
      }
      index = r.End();
    }
    if (entries.empty()) continue;
    const std::string stored = bag.Read(chunk.data_pos, chunk.data_length, what);
    // Stored as is, the chunk is its data whatever "size" says (rosbag_storage reads it so).
    const std::string content = compression == "none"  ? stored
                                : compression == "bz2" ? Bz2(stored, size, what)
                                                       : Lz4(stored, size, what);
    CheckChunk(content, entries, connections, what);
  }
}

}  // namespace

std::string BagDefect(const std::string& path) {
  try {
    BagFile bag(path);
    Check(bag);
  } catch (const Defect& d) {
    return d.what;
  }
  return "";
}

}  // namespace openable
