#include "npz.hpp"

#include <zip.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include "handcentric/core/errors.hpp"

namespace handcentric::props::npz {
namespace {

// Little-endian reads from a byte buffer, bounds-checked by the caller.
std::uint64_t read_le(const std::string& bytes, std::size_t at, int width) {
  std::uint64_t v = 0;
  for (int i = width - 1; i >= 0; --i)
    v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
  return v;
}

// A member is read in pieces of this size, never past the size the archive declares for it.
constexpr std::uint64_t kChunk = std::uint64_t{1} << 20;
// Deflate gives at most 1032 bytes for one compressed byte (zlib's maximum ratio), stored
// members one: a member that claims more is refused before anything is allocated for it.
constexpr std::uint64_t kDeflateRatio = 1032;

struct ZipDiscard {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};
struct ZipFileClose {
  void operator()(zip_file_t* file) const { zip_fclose(file); }
};

class Reader {
 public:
  Reader(std::string source, std::uint64_t max_bytes)
      : source_(std::move(source)), max_(max_bytes) {}

  // The archive's size, checked against the limit before libzip reads it.
  void set_size(std::uint64_t size) {
    if (size > max_)
      fail("it is " + std::to_string(size) + " bytes, above the limit of " + std::to_string(max_));
    size_ = size;
  }

  // Takes `source` (freed here on failure): libzip's checks of the zip structure on open
  // (ZIP_CHECKCONS: the local headers against the central directory).
  void open(zip_source_t* source) {
    zip_error_t error;
    zip_error_init(&error);
    archive_.reset(zip_open_from_source(source, ZIP_RDONLY | ZIP_CHECKCONS, &error));
    if (!archive_) {
      zip_source_free(source);
      const int code = zip_error_code_zip(&error);
      const std::string detail = zip_error_strerror(&error);
      zip_error_fini(&error);
      fail_zip(code, detail, "");
    }
    zip_error_fini(&error);
  }

  std::map<std::string, Array> read() {
    std::map<std::string, Array> out;
    const zip_int64_t entries = zip_get_num_entries(archive_.get(), 0);
    for (zip_int64_t i = 0; i < entries; ++i) {
      zip_stat_t st;
      zip_stat_init(&st);
      if (zip_stat_index(archive_.get(), static_cast<zip_uint64_t>(i), 0, &st) != 0)
        fail_zip(zip_get_error(archive_.get()), "");
      std::string name = (st.valid & ZIP_STAT_NAME) != 0 ? st.name : "";
      if (name.size() < 4 || name.compare(name.size() - 4, 4, ".npy") != 0)
        fail("member '" + name + "' is not a .npy array");
      const std::string npy = member(static_cast<zip_uint64_t>(i), st, name);
      name.resize(name.size() - 4);
      out[name] = parse_npy(npy, name);
    }
    return out;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw FileError("observations file '" + source_ + "': " + what +
                    "; write it with np.savez or np.savez_compressed (docs/AUDIT.md, \"Your own "
                    "observations\")");
  }

 private:
  // libzip's error in our words, for the archive (`member` empty) or one member. The archive's
  // and a member's errors are freed with them.
  [[noreturn]] void fail_zip(zip_error_t* error, const std::string& member) const {
    fail_zip(zip_error_code_zip(error), zip_error_strerror(error), member);
  }
  [[noreturn]] void fail_zip(int code, const std::string& detail, const std::string& member) const {
    const std::string which = member.empty() ? "it" : "member '" + member + "'";
    switch (code) {
      case ZIP_ER_NOZIP:
        fail("it is not a zip archive");
      case ZIP_ER_CRC:
        fail(which + " fails its CRC check (a corrupt file)");
      case ZIP_ER_EOF:
      case ZIP_ER_READ:
      case ZIP_ER_SEEK:
        fail(which + " is truncated (" + detail + ")");
      case ZIP_ER_INCONS:
        fail((member.empty() ? "it is a damaged zip archive" : which + " is damaged") + " (" +
             detail + ")");
      case ZIP_ER_ZLIB:
      case ZIP_ER_COMPRESSED_DATA:
        fail(which + " does not inflate (" + detail + ")");
      case ZIP_ER_ENCRNOTSUPP:
      case ZIP_ER_NOPASSWD:
      case ZIP_ER_WRONGPASSWD:
        fail(which + " is encrypted");
      case ZIP_ER_COMPNOTSUPP:
        fail(which + " uses a zip compression method other than stored and deflate");
      default:
        fail(which + " cannot be read as a zip archive (libzip: " + detail + ")");
    }
  }

  // One member's bytes, its sizes checked first and its CRC by libzip once read to the end.
  std::string member(zip_uint64_t index, const zip_stat_t& st, const std::string& name) const {
    const zip_uint64_t needed =
        ZIP_STAT_SIZE | ZIP_STAT_COMP_SIZE | ZIP_STAT_COMP_METHOD | ZIP_STAT_ENCRYPTION_METHOD;
    if ((st.valid & needed) != needed) fail("member '" + name + "' has no sizes");
    if (st.encryption_method != ZIP_EM_NONE) fail("member '" + name + "' is encrypted");
    if (st.comp_method != ZIP_CM_STORE && st.comp_method != ZIP_CM_DEFLATE)
      fail("member '" + name + "' uses zip compression method " + std::to_string(st.comp_method) +
           " (only stored and deflate are read)");
    if (st.size > max_)
      fail("member '" + name + "' is " + std::to_string(st.size) + " bytes, above the limit");
    if (st.comp_method == ZIP_CM_STORE && st.size != st.comp_size)
      fail("member '" + name + "' has two sizes");
    // What its compressed bytes, at most the whole file, can hold: the bound of the allocation.
    const std::uint64_t compressed = std::min<std::uint64_t>(st.comp_size, size_);
    const std::uint64_t can_hold =
        st.comp_method == ZIP_CM_STORE ? compressed : (compressed + 1) * kDeflateRatio;
    if (st.size > can_hold)
      fail("member '" + name + "' claims " + std::to_string(st.size) + " bytes from " +
           std::to_string(st.comp_size) + " compressed in a file of " + std::to_string(size_) +
           " (a corrupt file)");
    std::unique_ptr<zip_file_t, ZipFileClose> file(zip_fopen_index(archive_.get(), index, 0));
    if (!file) fail_zip(zip_get_error(archive_.get()), name);
    std::string out(static_cast<std::size_t>(st.size), '\0');
    std::uint64_t got = 0;
    for (;;) {
      // One byte past the declared size: libzip checks the CRC and the size when it reaches the
      // member's end, and a member longer than it says is refused here.
      char past = 0;
      const std::uint64_t want = std::min(kChunk, st.size - got);
      const zip_int64_t n = want > 0 ? zip_fread(file.get(), out.data() + got, want)
                                     : zip_fread(file.get(), &past, 1);
      if (n < 0) fail_zip(zip_file_get_error(file.get()), name);
      if (n == 0) break;
      if (want == 0)
        fail("member '" + name + "' is longer than its " + std::to_string(st.size) + " bytes");
      got += static_cast<std::uint64_t>(n);
    }
    if (got != st.size)
      fail("member '" + name + "' is " + std::to_string(got) + " bytes, not its " +
           std::to_string(st.size));
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
    const std::size_t order = header.find_first_not_of(' ', at);
    if (order == std::string::npos) fail(where + " has a bad 'fortran_order'");
    if (header.compare(order, 4, "True") == 0)
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

  std::string source_;
  std::uint64_t max_;
  std::uint64_t size_ = 0;
  std::unique_ptr<zip_t, ZipDiscard> archive_;
};

}  // namespace

std::map<std::string, Array> read(const std::string& path, std::uint64_t max_bytes) {
  Reader reader(path, max_bytes);
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError("cannot open observations file '" + path + "': check the path");
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw FileError("cannot read observations file '" + path + "'");
    reader.set_size(static_cast<std::uint64_t>(size));
  }
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* source = zip_source_file_create(path.c_str(), 0, -1, &error);
  if (source == nullptr) {
    zip_error_fini(&error);
    throw FileError("cannot read observations file '" + path + "'");
  }
  reader.open(source);
  return reader.read();
}

std::map<std::string, Array> read_bytes(std::string_view bytes, const std::string& source,
                                        std::uint64_t max_bytes) {
  Reader reader(source, max_bytes);
  reader.set_size(bytes.size());
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* buffer = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
  if (buffer == nullptr) {
    zip_error_fini(&error);
    reader.fail("libzip could not take its bytes");
  }
  reader.open(buffer);
  return reader.read();
}

}  // namespace handcentric::props::npz
