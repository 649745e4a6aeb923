// .npz (ZIP) archives written byte by byte for tests, after PKWARE's APPNOTE.TXT, so that they
// can hold what NumPy never writes: two members of one name, a size declared for more data
// than there are, a local header naming another file, an entry the end record does not count.
// The deflated members are deflate streams of stored blocks (RFC 1951, 3.2.4), and the CRC-32
// is computed here bit by bit, independently of the reader's libdeflate.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace openable::testing {

// CRC-32 of ZIP (reflected polynomial 0xEDB88320), bit by bit.
inline std::uint32_t ZipCrc32(std::string_view data) {
  std::uint32_t crc = 0xffffffffu;
  for (const char c : data) {
    crc ^= static_cast<unsigned char>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// `data` as a deflate stream of stored blocks of at most 65535 bytes.
inline std::string StoredDeflate(std::string_view data) {
  std::string out;
  std::size_t at = 0;
  do {
    const std::size_t n = std::min<std::size_t>(65535, data.size() - at);
    const bool last = at + n == data.size();
    out += static_cast<char>(last ? 1 : 0);  // BFINAL, BTYPE 00 (stored)
    for (const std::uint16_t v : {static_cast<std::uint16_t>(n), static_cast<std::uint16_t>(~n)}) {
      out += static_cast<char>(v & 0xff);
      out += static_cast<char>(v >> 8);
    }
    out.append(data.substr(at, n));
    at += n;
  } while (at < data.size());
  return out;
}

struct ZipEntry {
  ZipEntry(std::string n, std::string d, bool deflated = true, std::int64_t declared_size = -1)
      : name(std::move(n)), data(std::move(d)), deflate(deflated), declared(declared_size) {}
  std::string name;
  std::string data;            // the member's bytes once inflated
  bool deflate = true;         // method 8 (stored deflate blocks), else 0 (stored)
  std::int64_t declared = -1;  // the uncompressed size the headers declare (-1: data's size)
  std::string local_name;      // the local header's name (empty: `name`)
};

namespace zip_internal {
inline void Put(std::string& out, std::uint64_t v, int bytes) {
  for (int k = 0; k < bytes; ++k) out += static_cast<char>((v >> (8 * k)) & 0xff);
}
}  // namespace zip_internal

// The archive of `entries`, in this order. `announced`: the entry count the end record gives
// (-1: the real count). `before`: bytes the archive is appended to (its offsets then count from
// the start of the archive, not of the file, as when a ZIP is concatenated to another file).
inline std::string ZipArchive(const std::vector<ZipEntry>& entries, int announced = -1,
                              const std::string& before = "") {
  using zip_internal::Put;
  std::string local, directory;
  for (const ZipEntry& e : entries) {
    const std::string stored = e.deflate ? StoredDeflate(e.data) : e.data;
    const std::uint64_t size =
        e.declared >= 0 ? static_cast<std::uint64_t>(e.declared) : e.data.size();
    const std::string& local_name = e.local_name.empty() ? e.name : e.local_name;
    const std::uint64_t offset = local.size();
    Put(local, 0x04034b50, 4);
    Put(local, 20, 2);  // version needed
    Put(local, 0, 2);   // flags
    Put(local, e.deflate ? 8 : 0, 2);
    Put(local, 0, 4);  // time, date
    Put(local, ZipCrc32(e.data), 4);
    Put(local, stored.size(), 4);
    Put(local, size, 4);
    Put(local, local_name.size(), 2);
    Put(local, 0, 2);  // extra
    local += local_name + stored;
    Put(directory, 0x02014b50, 4);
    Put(directory, 20, 2);  // made by
    Put(directory, 20, 2);  // needed
    Put(directory, 0, 2);
    Put(directory, e.deflate ? 8 : 0, 2);
    Put(directory, 0, 4);
    Put(directory, ZipCrc32(e.data), 4);
    Put(directory, stored.size(), 4);
    Put(directory, size, 4);
    Put(directory, e.name.size(), 2);
    Put(directory, 0, 2);  // extra
    Put(directory, 0, 2);  // comment
    Put(directory, 0, 2);  // disk
    Put(directory, 0, 2);  // internal attributes
    Put(directory, 0, 4);  // external attributes
    Put(directory, offset, 4);
    directory += e.name;
  }
  const std::uint64_t count =
      announced >= 0 ? static_cast<std::uint64_t>(announced) : entries.size();
  std::string end;
  Put(end, 0x06054b50, 4);
  Put(end, 0, 4);  // disks
  Put(end, count, 2);
  Put(end, count, 2);
  Put(end, directory.size(), 4);
  Put(end, local.size(), 4);  // the directory's offset
  Put(end, 0, 2);             // comment
  return before + local + directory + end;
}

}  // namespace openable::testing
