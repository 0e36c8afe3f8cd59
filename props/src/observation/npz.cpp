#include "npz.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "handcentric/core/errors.hpp"

namespace handcentric::props::npz {
namespace {

// Little-endian reads from a byte buffer, bounds-checked by the caller's `need`.
std::uint64_t read_le(const std::string& bytes, std::size_t at, int width) {
  std::uint64_t v = 0;
  for (int i = width - 1; i >= 0; --i)
    v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
  return v;
}

class Reader {
 public:
  Reader(std::string path, std::uint64_t max_bytes) : path_(std::move(path)), max_(max_bytes) {}

  std::map<std::string, Array> read() {
    load();
    std::map<std::string, Array> out;
    for (const Member& m : members()) {
      std::string name = m.name;
      if (name.size() < 4 || name.compare(name.size() - 4, 4, ".npy") != 0)
        fail("member '" + name + "' is not a .npy array");
      name.resize(name.size() - 4);
      out[name] = parse_npy(inflate(m), name);
    }
    return out;
  }

 private:
  struct Member {
    std::string name;
    int method = 0;
    std::uint32_t crc = 0;
    std::uint64_t compressed = 0, size = 0, local_offset = 0;
  };

  [[noreturn]] void fail(const std::string& what) const {
    throw FileError("observations file '" + path_ + "': " + what +
                    "; write it with np.savez or np.savez_compressed (docs/AUDIT.md, \"Your own "
                    "observations\")");
  }

  void need(std::uint64_t at, std::uint64_t count, const char* what) const {
    if (at > bytes_.size() || count > bytes_.size() - at) fail(std::string("truncated ") + what);
  }

  void load() {
    std::ifstream in(path_, std::ios::binary);
    if (!in) throw FileError("cannot open observations file '" + path_ + "': check the path");
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw FileError("cannot read observations file '" + path_ + "'");
    if (static_cast<std::uint64_t>(size) > max_)
      fail("it is " + std::to_string(size) + " bytes, above the limit of " + std::to_string(max_));
    in.seekg(0);
    bytes_.resize(static_cast<std::size_t>(size));
    if (!in.read(bytes_.data(), size))
      throw FileError("cannot read observations file '" + path_ + "'");
  }

  std::vector<Member> members() const {
    // The end of central directory record: the last one within 64 KiB + 22 bytes of the end.
    if (bytes_.size() < 22) fail("it is not a zip archive (too short)");
    std::size_t eocd = std::string::npos;
    const std::size_t lowest = bytes_.size() > 65557 ? bytes_.size() - 65557 : 0;
    for (std::size_t at = bytes_.size() - 22 + 1; at-- > lowest;) {
      if (read_le(bytes_, at, 4) == 0x06054b50U) {
        eocd = at;
        break;
      }
    }
    if (eocd == std::string::npos) fail("it is not a zip archive (no end of central directory)");
    std::uint64_t entries = read_le(bytes_, eocd + 10, 2);
    std::uint64_t cd_offset = read_le(bytes_, eocd + 16, 4);
    if (entries == 0xFFFFU || cd_offset == 0xFFFFFFFFU) {  // zip64: the locator comes first
      if (eocd < 20 || read_le(bytes_, eocd - 20, 4) != 0x07064b50U)
        fail("a zip64 archive without its locator");
      const std::uint64_t z64 = read_le(bytes_, eocd - 20 + 8, 8);
      need(z64, 56, "zip64 end of central directory");
      if (read_le(bytes_, z64, 4) != 0x06064b50U) fail("a bad zip64 end of central directory");
      entries = read_le(bytes_, z64 + 32, 8);
      cd_offset = read_le(bytes_, z64 + 48, 8);
    }
    if (entries > bytes_.size() / 46)
      fail("a central directory of " + std::to_string(entries) + " entries");
    std::vector<Member> out;
    std::uint64_t at = cd_offset;
    for (std::uint64_t e = 0; e < entries; ++e) {
      need(at, 46, "central directory");
      if (read_le(bytes_, at, 4) != 0x02014b50U) fail("a bad central directory entry");
      Member m;
      const std::uint64_t flags = read_le(bytes_, at + 8, 2);
      if ((flags & 1U) != 0) fail("an encrypted member");
      m.method = static_cast<int>(read_le(bytes_, at + 10, 2));
      m.crc = static_cast<std::uint32_t>(read_le(bytes_, at + 16, 4));
      m.compressed = read_le(bytes_, at + 20, 4);
      m.size = read_le(bytes_, at + 24, 4);
      const std::uint64_t name_length = read_le(bytes_, at + 28, 2);
      const std::uint64_t extra_length = read_le(bytes_, at + 30, 2);
      const std::uint64_t comment_length = read_le(bytes_, at + 32, 2);
      m.local_offset = read_le(bytes_, at + 42, 4);
      need(at + 46, name_length + extra_length + comment_length, "central directory entry");
      m.name =
          bytes_.substr(static_cast<std::size_t>(at + 46), static_cast<std::size_t>(name_length));
      // The zip64 extra field holds, in this order, the sizes and offset whose 32-bit fields are
      // all ones.
      std::uint64_t x = at + 46 + name_length;
      const std::uint64_t x_end = x + extra_length;
      while (x + 4 <= x_end) {
        const std::uint64_t id = read_le(bytes_, x, 2), length = read_le(bytes_, x + 2, 2);
        if (x + 4 + length > x_end) fail("a bad extra field");
        if (id == 1) {
          std::uint64_t y = x + 4;
          auto take = [&](std::uint64_t& field) {
            if (field != 0xFFFFFFFFU) return;
            if (y + 8 > x + 4 + length) fail("a short zip64 extra field");
            field = read_le(bytes_, y, 8);
            y += 8;
          };
          take(m.size);
          take(m.compressed);
          take(m.local_offset);
        }
        x += 4 + length;
      }
      out.push_back(std::move(m));
      at = x_end + comment_length;
    }
    return out;
  }

  std::string inflate(const Member& m) const {
    if (m.size > max_)
      fail("member '" + m.name + "' is " + std::to_string(m.size) + " bytes, above the limit");
    need(m.local_offset, 30, "local header");
    if (read_le(bytes_, m.local_offset, 4) != 0x04034b50U) fail("a bad local header");
    const std::uint64_t data = m.local_offset + 30 + read_le(bytes_, m.local_offset + 26, 2) +
                               read_le(bytes_, m.local_offset + 28, 2);
    need(data, m.compressed, "member data");
    std::string out;
    if (m.method == 0) {
      if (m.compressed != m.size) fail("member '" + m.name + "' has two sizes");
      out = bytes_.substr(static_cast<std::size_t>(data), static_cast<std::size_t>(m.size));
    } else if (m.method == 8) {
      out.resize(static_cast<std::size_t>(m.size));
      z_stream stream{};
      if (inflateInit2(&stream, -MAX_WBITS) != Z_OK) fail("zlib could not start");
      stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes_.data() + data));
      stream.avail_in = static_cast<uInt>(
          std::min<std::uint64_t>(m.compressed, std::numeric_limits<uInt>::max()));
      stream.next_out = reinterpret_cast<Bytef*>(out.data());
      stream.avail_out =
          static_cast<uInt>(std::min<std::uint64_t>(m.size, std::numeric_limits<uInt>::max()));
      const int status = ::inflate(&stream, Z_FINISH);
      const std::uint64_t produced = stream.total_out;
      inflateEnd(&stream);
      if (status != Z_STREAM_END || produced != m.size)
        fail("member '" + m.name + "' does not inflate to its " + std::to_string(m.size) +
             " bytes");
    } else {
      fail("member '" + m.name + "' uses zip compression method " + std::to_string(m.method) +
           " (only stored and deflate are read)");
    }
    if (out.size() <= std::numeric_limits<uInt>::max() &&
        crc32(0L, reinterpret_cast<const Bytef*>(out.data()), static_cast<uInt>(out.size())) !=
            m.crc)
      fail("member '" + m.name + "' fails its CRC check (a corrupt file)");
    return out;
  }

  Array parse_npy(const std::string& npy, const std::string& name) const {
    const std::string where = "array '" + name + "'";
    if (npy.size() < 10 || npy.compare(0, 6, "\x93NUMPY") != 0)
      fail(where + " is not in .npy format");
    const int major = static_cast<unsigned char>(npy[6]);
    std::size_t header_length = 0, header_at = 0;
    if (major == 1) {
      header_length = static_cast<std::size_t>(read_le(npy, 8, 2));
      header_at = 10;
    } else if (major == 2 || major == 3) {
      if (npy.size() < 12) fail(where + " is truncated");
      header_length = static_cast<std::size_t>(read_le(npy, 8, 4));
      header_at = 12;
    } else {
      fail(where + " has .npy format version " + std::to_string(major));
    }
    if (header_at + header_length > npy.size()) fail(where + " is truncated");
    const std::string header = npy.substr(header_at, header_length);
    auto value_after = [&](const std::string& key) {
      const std::size_t k = header.find("'" + key + "'");
      if (k == std::string::npos) fail(where + " has no '" + key + "' in its header");
      const std::size_t colon = header.find(':', k);
      if (colon == std::string::npos) fail(where + " has a bad header");
      return colon + 1;
    };
    Array out;
    std::size_t at = value_after("descr");
    const std::size_t open = header.find('\'', at);
    const std::size_t close = open == std::string::npos ? open : header.find('\'', open + 1);
    if (close == std::string::npos) fail(where + " has a bad 'descr'");
    out.dtype = header.substr(open + 1, close - open - 1);
    at = value_after("fortran_order");
    if (header.compare(header.find_first_not_of(' ', at), 4, "True") == 0)
      fail(where + " is in Fortran order: save np.ascontiguousarray(x)");
    at = value_after("shape");
    const std::size_t paren = header.find('(', at), end = header.find(')', at);
    if (paren == std::string::npos || end == std::string::npos || end < paren)
      fail(where + " has a bad 'shape'");
    std::istringstream sizes(header.substr(paren + 1, end - paren - 1));
    std::string token;
    std::uint64_t count = 1;
    while (std::getline(sizes, token, ',')) {
      if (token.find_first_not_of(' ') == std::string::npos) continue;
      std::int64_t size = -1;
      try {
        size = std::stoll(token);
      } catch (...) {
      }
      if (size < 0) fail(where + " has a bad size '" + token + "' in its shape");
      out.shape.push_back(size);
      if (size > 0 && count > max_ / static_cast<std::uint64_t>(size))
        fail(where + " is too large");
      count *= static_cast<std::uint64_t>(size);
    }
    // Little-endian (or byte-sized) numbers only: what NumPy writes on this machine's kind.
    struct Kind {
      const char* descr;
      int bytes;
    };
    static const Kind kinds[] = {{"<f8", 8}, {"<f4", 4}, {"|u1", 1}, {"|i1", 1},
                                 {"|b1", 1}, {"<i2", 2}, {"<u2", 2}, {"<i4", 4},
                                 {"<u4", 4}, {"<i8", 8}, {"<u8", 8}};
    const Kind* kind = nullptr;
    for (const Kind& k : kinds)
      if (out.dtype == k.descr) kind = &k;
    if (kind == nullptr)
      fail(where + " has dtype '" + out.dtype + "': save it as float64 (x.astype('<f8'))");
    const std::size_t body = header_at + header_length;
    if (npy.size() - body != count * static_cast<std::uint64_t>(kind->bytes))
      fail(where + " holds " + std::to_string(npy.size() - body) + " bytes for its shape");
    out.float32 = out.dtype == "<f4";
    out.values.resize(static_cast<std::size_t>(count));
    const char* p = npy.data() + body;
    const std::string& d = out.dtype;
    for (std::size_t i = 0; i < out.values.size(); ++i, p += kind->bytes) {
      if (d == "<f8") {
        double v;
        std::memcpy(&v, p, 8);
        out.values[i] = v;
      } else if (d == "<f4") {
        float v;
        std::memcpy(&v, p, 4);
        out.values[i] = v;
      } else if (d[1] == 'u' || d[1] == 'b') {
        out.values[i] = static_cast<double>(
            read_le(npy, static_cast<std::size_t>(p - npy.data()), kind->bytes));
      } else {
        const std::uint64_t raw =
            read_le(npy, static_cast<std::size_t>(p - npy.data()), kind->bytes);
        const int shift = 64 - 8 * kind->bytes;  // sign-extend
        out.values[i] = static_cast<double>(static_cast<std::int64_t>(raw << shift) >> shift);
      }
    }
    return out;
  }

  std::string path_;
  std::uint64_t max_;
  std::string bytes_;
};

}  // namespace

std::map<std::string, Array> read(const std::string& path, std::uint64_t max_bytes) {
  return Reader(path, max_bytes).read();
}

}  // namespace handcentric::props::npz
