// The .npz reader of recorded observations (props/src/observation/npz.*, on libzip): files as
// NumPy writes them (np.savez stored, np.savez_compressed deflated, and a zip64 archive) are
// read alike; damaged ones are refused with a FileError naming the file and the problem (a CRC
// mismatch, not a zip, truncated, a member that is not .npy, bzip2, Fortran order, no pose); and
// 300 deterministic mutations of small files (flipped bytes, cuts, sizes and counts rewritten in
// the zip headers, .npy headers rewritten with the CRC repaired) each load or throw
// handcentric::Error, never another exception, never a crash, never 256 MiB more memory.
#include <catch2/catch.hpp>

#include <stdlib.h>
#include <sys/resource.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "observation/npz.hpp"
#include "run_command.hpp"

using namespace handcentric;

namespace {

// The files of one Python run in a fresh folder: 3 observations (history, a goal, a gripper
// width, uint8 "ids") as np.savez, np.savez_compressed and a zip64 archive (zipfile's zip64
// limit lowered to 0: zip64 end records and extra fields everywhere), and the bad ones.
class NpzFiles {
 public:
  NpzFiles() {
    char folder[] = "/tmp/handcentric_npz_XXXXXX";
    REQUIRE(mkdtemp(folder) != nullptr);
    dir_ = folder;
    std::ofstream script(dir_ + "/make.py");
    script << R"(import sys, zipfile
import numpy as np
d = sys.argv[1]
rng = np.random.default_rng(3)
history = np.tile(np.eye(4), (3, 2, 1, 1))
history[:, :, :3, 3] = rng.uniform(-0.5, 0.5, (3, 2, 3))
goal = np.tile(np.eye(4), (3, 1, 1))
goal[:, :3, 3] = rng.uniform(-0.5, 0.5, (3, 3))
arrays = {"history": history, "extra_poses/goal": goal,
          "scalars/gripper": np.array([0.25, 0.5, 0.75], dtype=np.float32),
          "held/ids": np.array([[3, 1, 4], [1, 5, 9], [2, 6, 5]], dtype=np.uint8)}
np.savez(d + "/stored.npz", **arrays)
np.savez_compressed(d + "/deflated.npz", **arrays)
np.savez(d + "/fortran.npz", history=np.asfortranarray(history))
np.savez(d + "/no_poses.npz", history=np.zeros((3, 0, 4, 4)))
with zipfile.ZipFile(d + "/text.npz", "w") as z:
    z.writestr("notes.txt", "not an array")
with zipfile.ZipFile(d + "/bzip2.npz", "w", compression=zipfile.ZIP_BZIP2) as z:
    z.writestr("history.npy", open(d + "/stored.npz", "rb").read())
zipfile.ZIP64_LIMIT = 0
np.savez_compressed(d + "/zip64.npz", **arrays)
)";
    script.close();
    const auto made = test::run_command(test::python() + " " + dir_ + "/make.py " + dir_);
    INFO(made.err);
    REQUIRE(made.exit_code == 0);
  }
  ~NpzFiles() {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  NpzFiles(const NpzFiles&) = delete;
  NpzFiles& operator=(const NpzFiles&) = delete;

  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string bytes(const std::string& name) const {
    std::ifstream in(path(name), std::ios::binary);
    std::stringstream out;
    out << in.rdbuf();
    return out.str();
  }

 private:
  std::string dir_;
};

std::uint64_t get_le(const std::string& s, std::size_t at, int width) {
  std::uint64_t v = 0;
  for (int i = width - 1; i >= 0; --i)
    v = (v << 8) | static_cast<unsigned char>(s.at(at + static_cast<std::size_t>(i)));
  return v;
}

void put_le(std::string& s, std::size_t at, int width, std::uint64_t v) {
  for (int i = 0; i < width && at + static_cast<std::size_t>(i) < s.size(); ++i)
    s[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

std::uint32_t crc32_of(const std::string& s, std::size_t at, std::size_t count) {
  std::uint32_t crc = 0xFFFFFFFFU;
  for (std::size_t i = at; i < at + count; ++i) {
    crc ^= static_cast<unsigned char>(s[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320U & (0U - (crc & 1U)));
  }
  return ~crc;
}

std::vector<std::size_t> find_all(const std::string& s, const std::string& what) {
  std::vector<std::size_t> out;
  for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1))
    out.push_back(at);
  return out;
}

// A member of an archive without zip64 central entries (np.savez's): where its CRCs are and
// where its data lies.
struct Member {
  std::size_t central = 0, local = 0, data = 0, size = 0;
};

std::vector<Member> members_of(const std::string& zip) {
  std::vector<Member> out;
  for (const std::size_t c : find_all(zip, "PK\x01\x02")) {
    Member m;
    m.central = c;
    m.size = static_cast<std::size_t>(get_le(zip, c + 20, 4));
    m.local = static_cast<std::size_t>(get_le(zip, c + 42, 4));
    m.data = m.local + 30 +
             static_cast<std::size_t>(get_le(zip, m.local + 26, 2) + get_le(zip, m.local + 28, 2));
    out.push_back(m);
  }
  return out;
}

// Both CRCs of a stored member set to its data's (after a mutation of the data).
void repair_crc(std::string& zip, const Member& m) {
  const std::uint32_t crc = crc32_of(zip, m.data, m.size);
  put_le(zip, m.central + 16, 4, crc);
  put_le(zip, m.local + 14, 4, crc);
}

// A stored member's .npy header text replaced by `text`, padded with spaces to its length (no
// newline), the CRC repaired: the array parser sees exactly `text`.
std::string with_npy_header(std::string zip, const Member& m, const std::string& text) {
  const std::size_t length = static_cast<std::size_t>(get_le(zip, m.data + 8, 2));
  REQUIRE(text.size() <= length);
  zip.replace(m.data + 10, length, text + std::string(length - text.size(), ' '));
  repair_crc(zip, m);
  return zip;
}

// The process's peak resident memory so far, in MiB.
long peak_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024;  // Linux: KiB
}

std::string load_error(const std::string& bytes) {
  try {
    (void)props::observations_from_npz(bytes, "test.npz");
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("npz_files_stored_deflated_and_zip64_are_read_alike_and_damaged_ones_refused", "[unit]") {
  const NpzFiles files;
  const std::string zip64 = files.bytes("zip64.npz");
  CHECK(zip64.find("PK\x06\x06") != std::string::npos);  // a zip64 end of central directory
  std::vector<props::RecordedObservations> read;
  for (const char* name : {"stored.npz", "deflated.npz", "zip64.npz"}) {
    INFO(name);
    read.push_back(props::read_observations(files.path(name)));
    const props::RecordedObservations& r = read.back();
    REQUIRE(r.scenes.size() == 3);
    CHECK(r.scenes[1].world_T_hand_history.size() == 2);
    CHECK(r.scenes[2].scalars.front().second == 0.75);
    CHECK(r.scenes[1].held.front().second->values == std::vector<double>{1, 5, 9});
    CHECK(r.scenes[0].extra_poses.front().first == "goal");
    for (std::size_t i = 0; i < 3; ++i) {
      CHECK(r.scenes[i].world_T_hand_history[1].matrix() ==
            read.front().scenes[i].world_T_hand_history[1].matrix());
      CHECK(r.scenes[i].extra_poses.front().second.matrix() ==
            read.front().scenes[i].extra_poses.front().second.matrix());
    }
  }
  // From memory as from the file.
  CHECK(props::observations_from_npz(zip64, "zip64.npz").scenes.size() == 3);

  // A CRC that does not match the data (both copies of it changed, so that the headers agree):
  // libzip's check when a member is read to its end.
  const std::string stored = files.bytes("stored.npz");
  const std::vector<Member> members = members_of(stored);
  REQUIRE(members.size() == 4);
  std::string bad_crc = stored;
  const std::uint64_t crc = get_le(bad_crc, members[0].central + 16, 4);
  put_le(bad_crc, members[0].central + 16, 4, crc ^ 1U);
  put_le(bad_crc, members[0].local + 14, 4, crc ^ 1U);
  CHECK_THAT(load_error(bad_crc), Catch::Matchers::Contains("test.npz") &&
                                      Catch::Matchers::Contains("fails its CRC check"));
  std::string flipped = stored;  // a number changed, the CRC left as it was
  flipped[members[0].data + members[0].size - 3] ^= 0x40;
  CHECK_THAT(load_error(flipped), Catch::Matchers::Contains("fails its CRC check"));
  std::string headers_disagree = stored;  // the central CRC only
  put_le(headers_disagree, members[0].central + 16, 4, crc ^ 1U);
  CHECK_THAT(load_error(headers_disagree), Catch::Matchers::Contains("observations file"));

  // A header that ends after "'fortran_order':" (found by fuzz_observations: std::out_of_range
  // from the parser) and one that says True.
  const std::string shape = "'shape': (3, 2, 4, 4), ";
  CHECK_THAT(load_error(with_npy_header(stored, members[0],
                                        "{'descr': '<f8', " + shape + "'fortran_order':")),
             Catch::Matchers::Contains("array 'history' has a bad 'fortran_order'"));
  CHECK_THAT(load_error(with_npy_header(stored, members[0],
                                        "{'descr': '<f8', " + shape + "'fortran_order': True}")),
             Catch::Matchers::Contains("Fortran order"));
  CHECK(load_error(with_npy_header(stored, members[0],
                                   "{'descr': '<f8', " + shape + "'fortran_order': False}")) ==
        "accepted");

  // Observations without a pose are refused before one is made per observation: 4e9 of them
  // in a file of no numbers must not allocate.
  const std::string no_poses = files.bytes("no_poses.npz");
  CHECK_THAT(load_error(no_poses), Catch::Matchers::Contains("shape (3, 0, 4, 4)") &&
                                       Catch::Matchers::Contains("H+1 >= 1"));
  CHECK_THAT(load_error(with_npy_header(
                 no_poses, members_of(no_poses).at(0),
                 "{'descr': '<f8', 'fortran_order': False, 'shape': (4000000000, 0, 4, 4), }")),
             Catch::Matchers::Contains("shape (4000000000, 0, 4, 4)"));

  CHECK_THAT(load_error("just text, no zip"), Catch::Matchers::Contains("not a zip archive"));
  CHECK_THAT(load_error(files.bytes("deflated.npz").substr(0, 300)),
             Catch::Matchers::Contains("test.npz"));
  const auto refused = [&](const char* name) {
    try {
      (void)props::read_observations(files.path(name));
    } catch (const FileError& e) {
      return std::string(e.what());
    }
    return std::string("accepted or another error");
  };
  CHECK_THAT(refused("text.npz"), Catch::Matchers::Contains("member 'notes.txt' is not a .npy"));
  CHECK_THAT(refused("bzip2.npz"), Catch::Matchers::Contains("compression method 12") &&
                                       Catch::Matchers::Contains("only stored and deflate"));
  CHECK_THAT(refused("fortran.npz"), Catch::Matchers::Contains("np.ascontiguousarray"));
  CHECK_THROWS_AS(props::read_observations(files.path("none.npz")), FileError);
}

TEST_CASE("300_mutated_npz_files_each_load_or_throw_a_handcentric_error", "[unit]") {
  const NpzFiles files;
  const std::vector<std::string> bases = {files.bytes("stored.npz"), files.bytes("deflated.npz"),
                                          files.bytes("zip64.npz")};
  std::mt19937_64 rng(20240611);
  const auto below = [&](std::size_t n) {
    return static_cast<std::size_t>(rng() % static_cast<std::uint64_t>(n));
  };
  // Sizes, counts and offsets: each field's width and offset in its record.
  struct Field {
    const char* signature;
    std::size_t at;
    int width;
  };
  static const Field fields[] = {
      {"PK\x03\x04", 18, 4}, {"PK\x03\x04", 22, 4}, {"PK\x03\x04", 26, 2}, {"PK\x03\x04", 28, 2},
      {"PK\x01\x02", 20, 4}, {"PK\x01\x02", 24, 4}, {"PK\x01\x02", 28, 2}, {"PK\x01\x02", 30, 2},
      {"PK\x01\x02", 42, 4}, {"PK\x05\x06", 10, 2}, {"PK\x05\x06", 12, 4}, {"PK\x05\x06", 16, 4},
      {"PK\x06\x06", 32, 8}, {"PK\x06\x06", 40, 8}, {"PK\x06\x06", 48, 8}};
  const std::vector<std::string> numbers = {
      "0", "1", "7", "4095", "-1", "x", "1000000000000", "4294967296", "99999999999999999999"};
  int loaded = 0, refused = 0, kinds[5] = {0, 0, 0, 0, 0};
  // A file of 2 KB must not make the reader allocate what its headers claim (up to 4 GiB).
  const long peak_before = peak_mib();
  for (int i = 0; loaded + refused < 300 && i < 1000; ++i) {
    const int kind = i % 5;
    std::string zip = bases[static_cast<std::size_t>(i / 5) % bases.size()];
    std::string what;
    if (kind == 0) {  // bytes flipped anywhere
      for (std::size_t k = 0, n = 1 + below(4); k < n; ++k) {
        const std::size_t at = below(zip.size());
        zip[at] = static_cast<char>(zip[at] ^ static_cast<char>(1 + below(255)));
        what += " flip@" + std::to_string(at);
      }
    } else if (kind == 1) {  // cut short
      zip.resize(below(zip.size()));
      what = " cut to " + std::to_string(zip.size());
    } else if (kind == 2) {  // a size, count or offset in a header rewritten
      const Field& f = fields[below(std::size(fields))];
      const std::vector<std::size_t> at = find_all(zip, f.signature);
      if (at.empty()) continue;
      const std::size_t where = at[below(at.size())] + f.at;
      if (where + static_cast<std::size_t>(f.width) > zip.size()) continue;
      const std::uint64_t old = get_le(zip, where, f.width);
      const std::uint64_t all = f.width == 8 ? ~std::uint64_t{0} : (1ULL << (8 * f.width)) - 1;
      const std::uint64_t choices[] = {0, 1, old + 1, old - 1, all, all >> 1, all - 1, rng()};
      const std::uint64_t value = choices[below(std::size(choices))] & all;
      put_le(zip, where, f.width, value);
      what = " field@" + std::to_string(where) + "=" + std::to_string(value);
    } else if (kind == 3) {  // two copies of a member's size rewritten alike
      const std::vector<Member> ms = members_of(bases[0]);
      zip = bases[0];
      const Member& m = ms[below(ms.size())];
      const std::uint64_t value = std::vector<std::uint64_t>{0,
                                                             1,
                                                             m.size - 1,
                                                             m.size + 1,
                                                             0xFFFFFFFEULL,
                                                             0x7FFFFFFFULL,
                                                             rng() & 0xFFFFFFFFULL}[below(7)];
      put_le(zip, m.central + 24, 4, value);  // central: uncompressed
      put_le(zip, m.central + 20, 4, value);  // central: compressed
      // np.savez's local header keeps its sizes in a zip64 extra field (id 1): size, compressed
      const std::size_t extra =
          m.local + 30 + static_cast<std::size_t>(get_le(zip, m.local + 26, 2));
      if (get_le(zip, extra, 2) == 1) {
        put_le(zip, extra + 4, 8, value);
        put_le(zip, extra + 12, 8, value);
      }
      what = " sizes=" + std::to_string(value);
    } else {  // a stored member's .npy rewritten, its CRC repaired: reaches the array parser
      zip = bases[0];
      const std::vector<Member> ms = members_of(zip);
      const Member& m = ms[below(ms.size())];
      std::string npy = zip.substr(m.data, m.size);
      const std::size_t shape = npy.find("'shape': (");
      const std::size_t header_end = npy.find('\n');
      if (below(2) == 0 || shape == std::string::npos || header_end == std::string::npos) {
        const std::size_t at = below(std::min<std::size_t>(npy.size(), 140));
        npy[at] = static_cast<char>(npy[at] ^ static_cast<char>(1 + below(255)));
        what = " npy flip@" + std::to_string(at);
      } else {  // a number of the shape replaced, the header's padding keeping its length
        const std::size_t from = shape + 10;
        const std::size_t to = npy.find_first_of(",)", from);
        const std::string number = numbers[below(numbers.size())];
        std::string header = npy.substr(0, header_end);
        header.replace(from, to - from, number);
        while (header.size() > header_end && header.back() == ' ') header.pop_back();
        if (header.size() > header_end) continue;
        header.append(header_end - header.size(), ' ');
        npy.replace(0, header_end, header);
        what = " shape " + number;
      }
      zip.replace(m.data, m.size, npy);
      repair_crc(zip, m);
    }
    ++kinds[kind];
    INFO("mutant " << i << ", kind " << kind << ":" << what);
    try {
      (void)props::observations_from_npz(zip, "mutant.npz");
      ++loaded;
    } catch (const Error& e) {
      ++refused;
      CHECK_THAT(e.what(), Catch::Matchers::Contains("mutant.npz"));
    } catch (const std::exception& e) {
      FAIL("not a handcentric::Error: " << e.what());
    }
    if (peak_mib() - peak_before > 256)
      FAIL("the peak memory grew by " << peak_mib() - peak_before << " MiB");
  }
  INFO("loaded " << loaded << ", refused " << refused);
  CHECK(loaded + refused == 300);  // a field rewrite without its record is skipped, not counted
  CHECK(refused > 200);
  for (const int k : kinds) CHECK(k > 40);
}
